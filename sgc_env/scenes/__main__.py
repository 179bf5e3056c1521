"""``python -m sgc_env.scenes``: rewrite the generated built-in ``three_rods.yaml`` from the path
functions of :mod:`sgc_env.scenes.three_rods`."""

from __future__ import annotations

from sgc_env.scenes.three_rods import write_three_rods_yaml

if __name__ == "__main__":
    print(write_three_rods_yaml())
