"""A rig's MATLAB export (a v4-v7 ``.mat`` file) as columns of numbers: variables, fields of a struct, elements of
a struct array, or columns and rows of a matrix, named in MATLAB's words."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from trms.errors import InputError, as_finite_array
from trms.rig.checks import ExportLayout

__all__ = ["is_mat_header", "read_mat_columns"]

#: The first bytes of MATLAB v5/v7 and v7.3 MAT-files, and the HDF5 signature (at byte 512 of a v7.3 file).
_MAT_MAGIC = (b"MATLAB 5.0 MAT-file", b"MATLAB 7.3 MAT-file")
_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
#: A trailing MATLAB matrix index of a .mat column: ``NAME(:,K)`` or ``NAME(K,:)`` (1-based).
_MATRIX_INDEX = re.compile(r"^(?P<base>.+?)\(\s*(?P<row>:|\d+)\s*,\s*(?P<col>:|\d+)\s*\)$")
_PART = re.compile(r"^(?P<name>[A-Za-z]\w*)(?:\(\s*(?P<index>\d+)\s*\))?$")


def is_mat_header(head: bytes) -> bool:
    """Whether the first bytes of a file are a MATLAB MAT-file's (v5/v7 or v7.3, or HDF5 at byte 512).

    Examples
    --------
    >>> is_mat_header(b"MATLAB 5.0 MAT-file, Platform: GLNXA64"), is_mat_header(b"time,V1,pitch")
    (True, False)
    """
    return head.startswith(_MAT_MAGIC) or head[512:520] == _HDF5_MAGIC


def _mat_variables(path: Path) -> dict[str, Any]:
    """The variables of a MATLAB v4-v7 file (structs as dicts, struct arrays as lists)."""
    import scipy.io

    try:
        with open(path, "rb") as fh:
            head = fh.read(520)
    except OSError as exc:
        raise InputError(f"MAT-file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    v73 = (
        f"{str(path)!r} is a MATLAB v7.3 (HDF5) MAT-file, which trms cannot read; save it as v7 in MATLAB "
        f"(save('{path.name}', ..., '-v7')) and import that"
    )
    if head.startswith(_MAT_MAGIC[1]) or head[512:520] == _HDF5_MAGIC:
        raise InputError(v73)
    if head.startswith(b"PK\x03\x04"):
        raise InputError(f"{str(path)!r} is a zip archive (a saved Record .npz?), not a MAT-file")
    try:
        mat = scipy.io.loadmat(path, simplify_cells=True)
    except NotImplementedError:
        raise InputError(v73) from None
    except Exception as exc:  # noqa: BLE001 -- scipy raises many kinds on a broken file; each becomes one line
        text = " ".join(str(exc).split()) or type(exc).__name__
        raise InputError(f"{str(path)!r} is not a MATLAB MAT-file trms can read ({text})") from None
    return {k: v for k, v in mat.items() if not k.startswith("__")}


def _describe(variables: dict[str, Any]) -> str:
    out = []
    for k, v in variables.items():
        if isinstance(v, dict):
            out.append(f"{k} (struct: {', '.join(v)})")
        elif isinstance(v, str):
            out.append(f"{k} (text)")
        elif isinstance(v, list):
            out.append(f"{k} (struct array of {len(v)})")
        else:
            shape = np.shape(v)
            out.append(f"{k} ({'x'.join(str(s) for s in shape) or 'scalar'})")
    return ", ".join(out) or "no variables"


def _mat_column(variables: dict[str, Any], spec: str, path: Path) -> np.ndarray:
    """One column of a .mat file named ``spec``: ``name``, ``struct.field``, ``s(2).values``, ``m(:,3)``."""
    where = f"{str(path)!r}"
    m = _MATRIX_INDEX.match(spec.strip())
    base: str = m["base"] if m else spec.strip()
    row: str = m["row"] if m else ""
    col: str = m["col"] if m else ""
    value: Any = variables
    parts = base.split(".")
    for depth, part in enumerate(parts):
        p = _PART.match(part)
        if p is None:
            raise InputError(f"{spec!r} is not a MAT-file variable name (e.g. t, data.pitch, log(:,2)) in {where}")
        if not isinstance(value, dict) or p["name"] not in value:
            if depth == 0 and len(parts) == 1:  # a field of a top-level struct, named alone
                owners = [k for k, v in variables.items() if isinstance(v, dict) and p["name"] in v]
                if len(owners) == 1:
                    value = variables[owners[0]]
                elif len(owners) > 1:
                    raise InputError(
                        f"{spec!r} is a field of several structs in {where} ({', '.join(owners)}); "
                        f"name one, e.g. {owners[0] + '.' + spec!r}"
                    )
            if not isinstance(value, dict) or p["name"] not in value:
                raise InputError(f"variable {spec!r} is missing from {where}; it has {_describe(variables)}")
        value = value[p["name"]]
        if p["index"] is not None:
            items = value if isinstance(value, list) else None
            k = int(p["index"])
            if items is None or not 1 <= k <= len(items):
                n = len(items) if items is not None else 1
                raise InputError(f"{spec!r}: {part!r} asks for element {k} of {n} in {where} (MATLAB counts from 1)")
            value = items[k - 1]
    if isinstance(value, dict):
        fields = list(value)
        raise InputError(
            f"variable {spec!r} of {where} is a struct (fields {', '.join(fields)}); name one of its fields, "
            f"e.g. {base + '.' + (fields[0] if fields else 'x')!r}"
        )
    if isinstance(value, list):
        raise InputError(
            f"variable {spec!r} of {where} is a struct array of {len(value)}; name an element, e.g. {base + '(1)'!r}"
        )
    arr = np.asarray(value)
    if m is not None:
        if arr.ndim != 2:
            raise InputError(f"variable {base!r} of {where} has shape {arr.shape}, not a matrix; {spec!r} needs one")
        rows, cols = arr.shape
        if row == ":" and col != ":" and 1 <= int(col) <= cols:
            arr = arr[:, int(col) - 1]
        elif col == ":" and row != ":" and 1 <= int(row) <= rows:
            arr = arr[int(row) - 1]
        else:
            raise InputError(
                f"{spec!r} is not a column of {base!r}, a {rows}x{cols} matrix of {where}: say {base}(:,K) with "
                f"K in 1..{cols} or {base}(K,:) with K in 1..{rows}"
            )
    arr = as_finite_array(f"variable {spec!r} of {where}", arr)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.ravel()
    if arr.ndim != 1:
        shape = "x".join(str(s) for s in arr.shape) or "one number"
        raise InputError(
            f"variable {spec!r} of {where} is {shape}, not one series; name one column, e.g. {base + '(:,1)'!r} "
            "(MATLAB counts from 1)"
        )
    return arr


def read_mat_columns(path: Path, layout: ExportLayout) -> tuple[np.ndarray, None, list[str], dict[str, Any]]:
    """The wanted columns of a .mat export as floats (one column each: time, inputs, outputs), no row numbers,
    no notes, and what was read (``{"format": "mat"}``).

    Raises
    ------
    InputError
        One line naming the variable: missing, a struct or matrix named without its column, complex or text,
        columns of different lengths, a v7.3 file.

    Examples
    --------
    >>> import tempfile, scipy.io
    >>> p = Path(tempfile.mkdtemp()) / "rig.mat"
    >>> scipy.io.savemat(p, {"log": np.column_stack([np.arange(3.0), np.ones(3), np.zeros(3)])})
    >>> lay = ExportLayout("log(:,1)", ("log(:,2)",), ("log(:,3)",), "deg", "s", False, ("u1",), ("pitch",))
    >>> read_mat_columns(p, lay)[0].shape
    (3, 3)
    """
    variables = _mat_variables(path)
    columns = [_mat_column(variables, spec, path) for spec in layout.wanted]
    lengths = {spec: c.size for spec, c in zip(layout.wanted, columns)}
    if len(set(lengths.values())) > 1:
        raise InputError(
            f"the columns of {str(path)!r} differ in length: "
            + ", ".join(f"{s!r} {n}" for s, n in lengths.items())
            + "; each needs one value per sample"
        )
    return np.column_stack(columns), None, [], {"format": "mat"}
