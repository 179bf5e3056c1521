"""Trusted model files into the formats ``sgc`` loads without unpickling (``sgc convert``).

A ``*.vecnormalize.pkl`` / ``vecnormalize.pkl`` / ``*_vecnormalize_<N>_steps.pkl`` (what SB3
and rl-zoo3 save) becomes the JSON statistics beside it, and the pickle goes
(:func:`~baselines.models.normalization.convert_pickle`); a model ``.zip`` loses the fields SB3
pickles from the last rollout (``_last_obs``, episode buffers ...), which prediction never
reads, every other member kept byte for byte. Converting UNPICKLES the ``.pkl`` files: only
for files you made or trust, which is why the command asks for ``--trust-model``.
"""

from __future__ import annotations

import io
import json
import zipfile
from collections.abc import Iterable
from pathlib import Path

from baselines.common.atomic_files import write_atomic
from baselines.models.model_files import read_model_data
from baselines.models.normalization import convert_pickle

__all__ = ["RUNTIME_FIELDS", "convert_files", "strip_runtime_state"]

RUNTIME_FIELDS = ("_last_obs", "_last_original_obs", "_last_episode_starts",
                  "ep_info_buffer", "ep_success_buffer")  # fmt: skip
"""Fields SB3 pickles from the last rollout; null in a converted zip."""


def strip_runtime_state(path: Path) -> bool:
    """Rewrite ``path`` with :data:`RUNTIME_FIELDS` set to null; True when it changed."""
    blob = path.read_bytes()
    data, _ = read_model_data(blob, str(path))
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


def _is_statistics(file: Path) -> bool:
    return file.suffix == ".pkl" and "vecnormalize" in file.name


def convert_files(paths: Iterable[Path]) -> list[str]:
    """Convert every statistics pickle and model zip among ``paths`` (files, or the files right
    in a folder); a line per file changed. A ValueError names a path that does not exist."""
    files: list[Path] = []
    for path in paths:
        if not path.exists():
            raise ValueError(f"{path}: no such file or folder")
        files += sorted(path.iterdir()) if path.is_dir() else [path]
    done = []
    for file in files:
        if _is_statistics(file):
            done.append(f"{file} -> {convert_pickle(file)}")
            file.unlink()
        elif file.suffix == ".zip" and strip_runtime_state(file):
            done.append(f"{file}: dropped the last rollout's pickled fields")
    return done
