"""Convert trusted model files to the formats ``sgc`` loads without unpickling.

    python scripts/convert_models.py [PATH ...]   # default: baselines/checkpoints

For each ``*.vecnormalize.pkl`` / ``vecnormalize.pkl`` / ``*_vecnormalize_<N>_steps.pkl``
(a file, or found in a folder) it writes the JSON statistics beside it and deletes the pickle
(:mod:`baselines.models.normalization`); for each ``.zip`` it drops the fields SB3 pickles from the
last rollout (``_last_obs``, episode buffers ...), which prediction does not read, keeping
every other member byte for byte. This UNPICKLES the ``.pkl`` files: run it only on files
you made or trust.
"""

from __future__ import annotations

import argparse
import io
import json
import zipfile
from pathlib import Path

from baselines.common.atomic_files import write_atomic
from baselines.models.model_files import read_model_data
from baselines.models.normalization import convert_pickle
from baselines.zoo.manifest import CHECKPOINTS

#: Fields SB3 pickles from the last rollout; null in a converted zip.
RUNTIME_FIELDS = ("_last_obs", "_last_original_obs", "_last_episode_starts",
                  "ep_info_buffer", "ep_success_buffer")  # fmt: skip


def strip_runtime_state(path: Path) -> bool:
    """Rewrite ``path`` with :data:`RUNTIME_FIELDS` set to null; True when it changed."""
    blob = path.read_bytes()
    data, names = read_model_data(blob, str(path))
    if not any(isinstance(data.get(k), dict) for k in RUNTIME_FIELDS):
        return False
    data.update({k: None for k in RUNTIME_FIELDS if k in data})
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(blob)) as source, zipfile.ZipFile(out, "w") as target:
        for info in source.infolist():
            content = source.read(info.filename)
            if info.filename == "data":
                content = json.dumps(data, indent=4).encode()
            target.writestr(info, content, compress_type=info.compress_type)
    write_atomic(path, out.getvalue())
    return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", type=Path, default=[CHECKPOINTS])
    args = parser.parse_args()
    files: list[Path] = []
    for path in args.paths:
        files += sorted(path.iterdir()) if path.is_dir() else [path]
    for file in files:
        if file.suffix == ".pkl" and "vecnormalize" in file.name:
            print(f"{file} -> {convert_pickle(file)}")
            file.unlink()
        elif file.suffix == ".zip" and strip_runtime_state(file):
            print(f"{file}: dropped the last rollout's pickled fields")


if __name__ == "__main__":
    main()
