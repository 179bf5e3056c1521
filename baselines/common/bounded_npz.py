"""An ``.npz`` from elsewhere, sized from its headers before any array is read.

``np.load`` allocates each array from the shape its ``.npy`` header claims, so a few bytes
can ask for 10^12 rows, and a compressed member can be a zip bomb. :func:`npz_shapes` reads
only the zip directory and each header (nothing unpickled, object arrays refused) and checks
the members, their declared sizes and each array's bytes against the caps first.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path

import numpy as np

from sgc_env.scenario.bounded import FileLimitError, check_count, escaped

__all__ = ["limit_rows", "npz_shapes"]

_HEADER_BYTES = 1 << 16
"""More than any ``.npy`` header numpy writes (it pads them to 64-byte multiples)."""


def npz_shapes(path: str | Path, where: str) -> dict[str, tuple[tuple[int, ...], np.dtype]]:
    """Array name -> (shape, dtype) of the npz at ``path``, once every cap holds; any fault
    is a :class:`FileLimitError` starting with ``where``."""
    out: dict[str, tuple[tuple[int, ...], np.dtype]] = {}
    try:
        with zipfile.ZipFile(path) as archive:
            infos = archive.infolist()
            check_count(len(infos), "zip_members", f"{where}: members")
            for info in infos:
                name = info.filename.removesuffix(".npy")
                field = f"{where}: array {escaped(name)!r}"
                check_count(info.file_size - _HEADER_BYTES, "npz_array_bytes",
                            f"{field} (declared size less a header)")  # fmt: skip
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(
                            member, max_header_size=_HEADER_BYTES)
                    else:
                        shape, _, dtype = np.lib.format.read_array_header_2_0(
                            member, max_header_size=_HEADER_BYTES)  # fmt: skip
                if dtype.hasobject:
                    raise FileLimitError(f"{field}: holds Python objects, which only "
                                         "unpickling restores: refused")  # fmt: skip
                size = math.prod(shape) * dtype.itemsize
                check_count(size, "npz_array_bytes", f"{field} of shape {shape}")
                if size > info.file_size:
                    raise FileLimitError(f"{field}: its header claims {size} bytes, the member "
                                         f"holds {info.file_size}")  # fmt: skip
                out[name] = (tuple(shape), dtype)
    except FileLimitError:
        raise
    except (zipfile.BadZipFile, OSError, EOFError, ValueError, TypeError, MemoryError) as exc:
        raise FileLimitError(f"{where}: not a readable npz ({type(exc).__name__}: "
                             f"{escaped(exc)})") from None  # fmt: skip
    return out


def limit_rows(shapes: dict[str, tuple[tuple[int, ...], np.dtype]], where: str) -> None:
    """Every array's first dimension within the ``demo_rows`` cap."""
    for name, (shape, _) in shapes.items():
        if shape:
            check_count(shape[0], "demo_rows", f"{where}: array {escaped(name)!r} rows")
