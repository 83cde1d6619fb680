"""Point clouds, the input of ``ccproof project`` and ``ccproof fit``: one reader, :func:`read_points`, for
``.xyz``, ``.ply``, ``.obj``, ``.csv`` (and any mesh format's vertices), and :func:`read_csv_columns`, the CSV
reader of the commands' tables (points, ``face,u,v`` rows). Every file goes through the input gate
(:func:`ccproof.mesh.inputs.checked_input`); every error names the file and the line.
"""

from __future__ import annotations

import os

import numpy as np

from ccproof.errors import CCProofError
from ccproof.mesh.inputs import checked_input
from ccproof.mesh.io import read_mesh

__all__ = ["read_points", "read_csv_columns", "POINT_FORMATS"]


#: the point-cloud formats of :func:`read_points` (``project`` and ``fit``); other extensions: a mesh's vertices
POINT_FORMATS = (".xyz", ".ply", ".obj", ".csv")


def read_points(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a point cloud, the input of ``ccproof project`` and ``ccproof fit``: ``.xyz``, ``.ply``, ``.obj``, ``.csv``.

    ``.xyz`` (also ``.txt``, ``.pts``): whitespace or comma columns x y z ... (more columns ignored, ``#``
    comments); ``.ply``: the vertex element (ASCII or binary); ``.obj``: the ``v`` lines; ``.csv``: the header
    ``x,y,z`` then one point a line (a byte-order mark and CRLF line ends accepted); any other extension: the
    vertices of :func:`read_mesh` (OFF, STL, VTK, ...). Read through the input gate
    (:func:`~ccproof.mesh.inputs.checked_input`: a regular file or a pipe, at most ``--max-input`` bytes).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    ndarray, shape (m, 3) float64, m >= 1, every coordinate finite

    Raises
    ------
    CCProofError
        Naming the file and the line (or vertex) of a bad, short or non-finite point, or an empty file.

    Examples
    --------
    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "cloud.csv")
    >>> with open(p, "w", newline="") as fh:
    ...     _ = fh.write("\\ufeffx,y,z\\r\\n1,2,3\\r\\n4,5,6\\r\\n")
    >>> read_points(p).tolist()
    [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    >>> with open(os.path.join(tmp.name, "c.xyz"), "w") as fh:
    ...     _ = fh.write("1 2 3 9\\n4 5\\n")
    >>> read_points(os.path.join(tmp.name, "c.xyz"))
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: .../c.xyz:2: expected 3 numbers x y z (more columns are ignored), got '4 5'
    """
    from pathlib import Path

    p = Path(path)
    with checked_input(p) as q:  # a regular file or a pipe, at most --max-input bytes
        X, where = _read_point_rows(p, Path(q))
    if X.shape[0] == 0:
        raise CCProofError(f"{p}: empty file (no points)")
    bad = np.flatnonzero(~np.isfinite(X).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise CCProofError(f"{p}:{where(i)}: point {i} has a non-finite coordinate {X[i].tolist()}")
    return X


def _read_point_rows(path, q):
    """(points (m, 3), where) of the file ``path`` read from ``q``; ``where(i)`` names point i's line or vertex."""
    ext = path.suffix.lower()
    if ext == ".csv":
        rows, lines = read_csv_columns(path, ("x", "y", "z"), read_from=q, with_lines=True)
        return rows, lambda i: int(lines[i])
    if ext in (".xyz", ".txt", ".pts", ".obj"):
        return _point_lines(path, q, ext == ".obj")
    if ext == ".ply":
        return _read_ply_vertices(path, q)
    if q.stat().st_size == 0:
        raise CCProofError(f"{path}: empty file (no points)")
    return np.asarray(read_mesh(q).vertices, dtype=np.float64).reshape(-1, 3), lambda i: f" vertex {i}"


def _point_lines(path, q, obj):
    """The points of an ``.xyz`` (x y z per line) or ``.obj`` (``v`` lines) file and their line numbers."""
    from ccproof.mesh.inputs import decode_text

    text = decode_text(q.read_bytes(), path, expect="'v x y z' lines" if obj else "lines of numbers x y z")
    if not obj:  # numpy's parser (twice as fast) when every line has the same columns; else the loop names the line
        X = _uniform_columns(text)
        if X is not None:
            return X, lambda i: _text_points(path, text, obj)[1](i)
    return _text_points(path, text, obj)


def _uniform_columns(text):
    """x, y, z of a text of whitespace columns (at least 3, the same on every line, ``#`` comments), or None."""
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an empty text: numpy warns; the caller's empty-file error follows
            A = np.loadtxt(text.splitlines(), dtype=np.float64, comments="#", ndmin=2)
    except ValueError:
        return None
    return A[:, :3].copy() if A.shape[1] >= 3 else None


def _text_points(path, text, obj):
    """The points of the text of an ``.xyz`` or ``.obj`` file and where(i), the line of point i, line by line."""
    rows, lines = [], []
    for ln, line in enumerate(text.splitlines(), 1):
        if obj:
            s = line.split()
            if not s or s[0] != "v":
                continue
            s = s[1:]
        else:
            s = line.split("#", 1)[0].replace(",", " ").split()
            if not s:
                continue
        try:
            if len(s) < 3:
                raise ValueError
            rows.append([float(x) for x in s[:3]])
        except ValueError:
            what = "bad vertex line" if obj else "expected 3 numbers x y z (more columns are ignored), got"
            raise CCProofError(f"{path}:{ln}: {what} {line.strip()!r}" + (" (needs 'v x y z')" if obj else "")) \
                from None
        lines.append(ln)
    return np.array(rows, dtype=np.float64).reshape(-1, 3), lambda i: lines[i]


def read_csv_columns(path, header, *, read_from=None, with_lines=False):
    """Rows of a CSV file whose first line is exactly ``header`` (e.g. ``("face", "u", "v")``), as floats
    (n, len(header)); blank lines are skipped; a byte-order mark and CRLF accepted; a bad header, row length or
    value raises :class:`CCProofError` naming the file and line. ``read_from``: the path actually read (a pipe's
    copy), ``path`` by default; ``with_lines``: also return the line number of every row.

    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> p = os.path.join(tmp.name, "p.csv")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("face,u,v\\n0,0.5\\n")
    >>> read_csv_columns(p, ("face", "u", "v"))
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: .../p.csv:2: expected 3 comma-separated values, got '0,0.5'
    """
    from ccproof.mesh.inputs import decode_text, read_input_text

    want = ",".join(header)
    expect = f"a CSV file with the header {want}"
    if read_from is None:  # through the input gate
        lines = read_input_text(path, expect=expect).splitlines()
    else:
        lines = decode_text(read_from.read_bytes(), path, expect=expect).splitlines()
    first = lines[0] if lines else ""
    if [h.strip().lower() for h in first.strip().split(",")] != list(header):
        raise CCProofError(f"{path}: the first line must be the header '{want}', got {first.strip()!r}")
    rows, numbers = [], []
    for no, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        parts = line.split(",")
        if len(parts) != len(header):
            raise CCProofError(f"{path}:{no}: expected {len(header)} comma-separated values, got {line.strip()!r}")
        try:
            rows.append([float(x) for x in parts])
        except ValueError:
            raise CCProofError(f"{path}:{no}: bad value in {line.strip()!r}") from None
        numbers.append(no)
    out = np.array(rows, dtype=np.float64).reshape(-1, len(header))
    return (out, numbers) if with_lines else out


_PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
              "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1", "int16": "i2", "uint16": "u2",
              "int32": "i4", "uint32": "u4", "float32": "f4", "float64": "f8"}


def _ply_vertex_header(path, data):
    """(format, number of vertices, [(property, dtype)], body bytes) of a PLY file whose first element is vertex."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise CCProofError(f"{path}: not a PLY file (it must start with the line 'ply' and have 'end_header')")
    header = data[:end].decode("ascii", "replace").splitlines()
    nl = data.find(b"\n", end)
    body = data[nl + 1:] if nl >= 0 else b""
    fmt, elements = None, []
    for no, line in enumerate(header, 1):
        s = line.split()
        if not s:
            continue
        if s[0] == "format" and len(s) > 1:
            fmt = s[1]
        elif s[0] == "element":
            if len(s) < 3 or not s[2].isdigit():
                raise CCProofError(f"{path}:{no}: bad element line {line.strip()!r}")
            elements.append([s[1], int(s[2]), []])
        elif s[0] == "property" and elements:
            elements[-1][2].append((s[-1], "list") if len(s) > 1 and s[1] == "list" else
                                   (s[-1], _PLY_TYPES.get(s[1]) if len(s) > 2 else None))
    if not elements or elements[0][0] != "vertex":
        raise CCProofError(f"{path}: the first PLY element must be 'vertex'")
    _, nv, props = elements[0]
    if any(t in (None, "list") for _, t in props) or not {"x", "y", "z"} <= {n for n, _ in props}:
        raise CCProofError(f"{path}: the vertex element needs scalar properties x, y, z")
    return fmt, nv, props, body


def _read_ply_vertices(path, q):
    """(x, y, z of the vertex element of a PLY file (ASCII or binary), where(i): the line or vertex of point i)."""
    data = q.read_bytes()
    fmt, nv, props, body = _ply_vertex_header(path, data)
    names = [n for n, _ in props]
    if fmt == "ascii":
        first = data[: len(data) - len(body)].count(b"\n") + 1  # the line of vertex 0
        rows = [ln.split()[: len(props)] for ln in body.decode("ascii", "replace").split("\n")[:nv]]
        short = next((i for i, r in enumerate(rows) if len(r) < len(props)), len(rows))
        if short < nv:
            raise CCProofError(f"{path}:{first + short}: truncated vertex list (the header declares {nv} vertices "
                               f"of {len(props)} properties)")
        try:
            A = np.array(rows, dtype=np.float64)
        except ValueError:
            bad = next(i for i, r in enumerate(rows) if not _all_numbers(r))
            raise CCProofError(f"{path}:{first + bad}: not a number in vertex {bad}") from None
        return A[:, [names.index(k) for k in "xyz"]], lambda i: first + i
    if fmt in ("binary_little_endian", "binary_big_endian"):
        bo = "<" if fmt == "binary_little_endian" else ">"
        dt = np.dtype([(n, bo + t) for n, t in props])
        if len(body) < nv * dt.itemsize:
            raise CCProofError(f"{path}: truncated vertex list (the header declares {nv} vertices)")
        rec = np.frombuffer(body[: nv * dt.itemsize], dtype=dt)
        return np.stack([rec["x"], rec["y"], rec["z"]], axis=1).astype(np.float64), lambda i: f" vertex {i}"
    raise CCProofError(f"{path}: unknown PLY format {fmt!r}")


def _all_numbers(words):
    try:
        [float(w) for w in words]
    except ValueError:
        return False
    return True
