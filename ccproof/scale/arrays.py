"""Chunk-wise evaluation of a limit surface and point sets kept as a folder of ``.npz`` shards.

The surface is never imported here: it comes as a :class:`~ccproof.scale.shipping.Shipped` builder
call (e.g. ``ship(limit_surface, mesh)``) and only its ``evaluate(face, u, v, derivatives=..., **kw)``
is called, on each chunk, with the same numpy arrays the serial evaluation would see; the chunk
results are concatenated, so a chunked or distributed evaluation is bit-identical to one call on
all points (each point is evaluated independently of the others).

Shard folder (``ccproof eval --out FOLDER``): ``index.json`` ({"format": "ccproof.shards/1", "n": total
points, "arrays": names, "shards": [{"file": "part-00000.npz", "n": points}, ...]}) and one
``part-NNNNN.npz`` per chunk holding ``face`` (int64, (m,)), ``u``, ``v`` (float64, (m,)) and each
result array (float64, (m, 3)), in point order.
"""

from __future__ import annotations

import json
from pathlib import Path

from ccproof.errors import CCProofError

from .shipping import rebuild

SHARDS_FORMAT = "ccproof.shards/1"
_KEYS = {0: ("P",), 1: ("P", "Pu", "Pv"), 2: ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")}


def output_names(derivatives):
    """The result arrays for a derivative order: P; Pu, Pv; Puu, Puv, Pvv.

    Parameters
    ----------
    derivatives : {0, 1, 2}
        Highest derivative order evaluated.

    Returns
    -------
    tuple of str

    Raises
    ------
    CCProofError
        For any other order.

    Examples
    --------
    >>> output_names(0), output_names(2)
    (('P',), ('P', 'Pu', 'Pv', 'Puu', 'Puv', 'Pvv'))
    """
    if derivatives not in _KEYS:
        raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
    return _KEYS[derivatives]


def _evaluate_block(face, u, v, shipped, derivatives, kwargs):
    """(on a worker) evaluate one chunk; returns shape (m, n_outputs, 3)."""
    import numpy as np

    out = rebuild(shipped).evaluate(face, u, v, derivatives=derivatives, **dict(kwargs))
    return np.stack([np.asarray(out[n], dtype=np.float64) for n in output_names(derivatives)], axis=1)


def evaluate_dask(shipped, face, u, v, derivatives=1, **kwargs):
    """Evaluate the shipped surface at dask arrays of points, one task per chunk (``map_blocks``).

    docs/scale-out.md, "Chunked evaluation".

    Parameters
    ----------
    shipped : Shipped
        ``ship(limit_surface, mesh, ...)``: sent once per worker, built once per worker process.
    face : dask or numpy array of int, shape (n,)
    u, v : dask or numpy arrays of float, shape (n,)
        Rechunked to the chunks of ``face``.
    derivatives : int
    kwargs
        Passed to ``evaluate`` (e.g. ``parameterization="characteristic"``).

    Returns
    -------
    dict of str -> dask array of shape (n, 3)
        ``P`` (and ``Pu``, ``Pv``; ``Puu``, ``Puv``, ``Pvv``), lazy; equal to the bit to
        ``surface.evaluate(face, u, v)`` on the same points.

    Examples
    --------
    The limit point at the centre of a face of the cube with corners (+-1, +-1, +-1) is at distance
    68/81 from the centre (one Catmull-Clark step by hand, then the regular limit mask (16, 4, 1)/36):

    >>> import dask.array as da
    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.reparam.surface import limit_surface
    >>> from ccproof.scale import ship
    >>> P = evaluate_dask(ship(limit_surface, cube()), da.from_array([0, 0], chunks=1), [0.5, 0.5],
    ...                   [0.5, 0.5], derivatives=0)["P"]
    >>> P.chunks[0], bool(abs(abs(P.compute(scheduler="sync")[0, 2]) - 68 / 81) < 1e-12)
    ((1, 1), True)
    """
    import dask
    import dask.array as da
    import numpy as np
    from dask.base import tokenize

    face = da.asarray(face)
    u = da.asarray(u).rechunk(face.chunks)
    v = da.asarray(v).rechunk(face.chunks)
    if face.ndim != 1 or u.shape != face.shape or v.shape != face.shape:
        raise CCProofError(f"face, u, v must be 1-D arrays of one length, got shapes {face.shape}, {u.shape}, "
                           f"{v.shape}")
    names = output_names(derivatives)
    ref = dask.delayed(shipped, pure=True, traverse=False)
    kw = tuple(sorted(kwargs.items()))
    # the keys name everything the result depends on: a cluster still holding the blocks of an earlier
    # evaluation of the same surface (other points, derivatives or parameterization) must not return them
    token = tokenize(shipped.digest, face.name, u.name, v.name, derivatives, kw)
    arr = da.map_blocks(_evaluate_block, face, u, v, ref, derivatives, kw,
                        new_axis=[1, 2], chunks=(face.chunks[0], (len(names),), (3,)), dtype=np.float64,
                        meta=np.empty((0, len(names), 3)), name=f"evaluate-{shipped.digest[:12]}-{token}")
    return {n: arr[:, j, :] for j, n in enumerate(names)}


# ---------------------------------------------------------------- chunks of a point set


def _sample_chunk(seed, n_faces, count, index):
    """Random points of chunk ``index``: uniform face and (u, v), from ``default_rng(seed)`` for chunk 0
    (so one chunk equals the unchunked draw ``f = integers(0, n_faces, count); u = random(count);
    v = random(count)``) and ``default_rng([seed, index])`` for the others. ``n_faces`` may also be an
    array of the face ids to draw from (uniformly)."""
    import numpy as np

    rng = np.random.default_rng(seed if index == 0 else [seed, index])
    if np.ndim(n_faces):  # the faces to draw from (a mesh with holes: the others), uniformly
        faces = np.asarray(n_faces, dtype=np.int64)
        return faces[rng.integers(0, faces.size, count)], rng.random(count), rng.random(count)
    return rng.integers(0, n_faces, count), rng.random(count), rng.random(count)


def _chunk_points(source):
    """The (face, u, v) numpy arrays of one chunk description (see :func:`_evaluate_chunk`)."""
    import numpy as np

    kind = source[0]
    if kind == "samples":
        return _sample_chunk(*source[1:])
    if kind == "arrays":
        return tuple(np.asarray(a) for a in source[1:])
    if kind == "shard":
        return _read_shard_points(source[1])
    raise CCProofError(f"unknown chunk source {kind!r}")


def _read_shard_points(path):
    """(face, u, v) of one shard file, a truncated or foreign file refused naming it."""
    import zipfile

    import numpy as np

    try:
        with np.load(path, allow_pickle=False) as z:
            face, u, v = z["face"], z["u"], z["v"]
    except (zipfile.BadZipFile, EOFError, ValueError, KeyError, OSError) as exc:
        why = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CCProofError(f"{path}: not a readable shard of points face, u, v (truncated or another file?): "
                           f"{why}") from None
    if not face.shape == u.shape == v.shape or face.ndim != 1:
        raise CCProofError(f"{path}: face, u, v of shapes {face.shape}, {u.shape}, {v.shape}: expected (n,) each")
    return face, u, v


def _evaluate_chunk(task, shipped):
    """One task of ``ccproof eval``: evaluate a chunk of points and write its shard (or return it).

    ``task`` is ``{"source": ("samples", seed, n_faces, count, index) | ("arrays", face, u, v) |
    ("shard", path), "derivatives": d, "kwargs": {...}, "out": path or None}``; returns the number of
    points written, :func:`degenerate_normals` of the shard and the seconds (setup, evaluation) of the task, or
    the dict face, u, v, P, ... and seconds when ``out`` is None.
    """
    import time

    import numpy as np

    f, u, v = _chunk_points(task["source"])
    t0 = time.perf_counter()
    rebuild(shipped)  # the setup: built once per process (this task may be the one that builds it)
    t1 = time.perf_counter()
    res = rebuild(shipped).evaluate(f, u, v, derivatives=task["derivatives"], **task["kwargs"])
    seconds = (t1 - t0, time.perf_counter() - t1)  # (setup, evaluation) in this task
    arrays = {"face": f, "u": u, "v": v}
    # the evaluator's own (n, 3) arrays, not stacked: no copy of the chunk's results
    arrays.update({n: np.asarray(res[n], dtype=np.float64) for n in output_names(task["derivatives"])})
    if task["out"] is None:
        return {**arrays, "seconds": seconds}
    _replace_when_written(task["out"], lambda tmp: np.savez(tmp, **arrays))
    return int(f.size), degenerate_normals(arrays), seconds


class DegenerateNormalWarning(UserWarning):
    """Evaluated points where ``Pu x Pv = 0``: the surface has no normal there (collapsed faces)."""


#: ``|Pu x Pv| <= NORMAL_TOLERANCE |Pu| |Pv|`` counts as no normal (0 = 0 too: a vanishing derivative)
NORMAL_TOLERANCE = 1e-12


def degenerate_normals(arrays):
    """(count, up to 6 faces) of the points of a result whose normal is undefined (``|Pu x Pv|`` at most
    :data:`NORMAL_TOLERANCE` times ``|Pu| |Pv|``); (0, []) without derivatives.

    >>> import numpy as np
    >>> degenerate_normals({"face": np.array([3, 4]), "Pu": np.array([[1.0, 0, 0], [1.0, 0, 0]]),
    ...                     "Pv": np.array([[0, 1.0, 0], [2.0, 0, 0]])})
    (1, [4])
    """
    import numpy as np

    if "Pu" not in arrays:
        return 0, []
    Pu, Pv = arrays["Pu"], arrays["Pv"]
    c = np.linalg.norm(np.cross(Pu, Pv), axis=1)
    bad = c <= NORMAL_TOLERANCE * np.linalg.norm(Pu, axis=1) * np.linalg.norm(Pv, axis=1)
    faces = np.unique(np.asarray(arrays["face"])[bad])
    return int(bad.sum()), [int(x) for x in faces[:6]]


def _warn_degenerate(n, counts):
    """One warning for the points without a normal (count, and the first faces), if any."""
    import warnings

    k = sum(c for c, _ in counts)
    if k:
        faces = sorted({f for _, fs in counts for f in fs})
        warnings.warn(f"{k} of {n} points have no normal (|Pu x Pv| = 0: a collapsed or degenerate face there), "
                      f"in faces {', '.join(map(str, faces[:5]))}{', ...' if len(faces) > 5 else ''}",
                      DegenerateNormalWarning, stacklevel=3)


def _replace_when_written(path, write):
    """``write(tmp)`` to a hidden name in the folder of ``path``, then rename it onto ``path``: a shard or
    index interrupted while being written never lies under its final name (the temporary name ends with
    the final one, so numpy's ``.npz`` is kept). An ``OSError`` of the writer (a full disk) names ``path``."""
    import os
    import uuid

    path = Path(path)
    tmp = path.with_name(f".tmp-{os.getpid()}-{uuid.uuid4().hex[:6]}-{path.name}")  # a dead writer's: removed later
    try:
        write(str(tmp))
        os.replace(tmp, path)
    except OSError as exc:  # a full disk: numpy's writer names no file (or our hidden one); the error names ours
        if exc.filename is None or str(exc.filename) == str(tmp):
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise
    finally:
        if tmp.exists():
            tmp.unlink()


def _shard_name(i):
    return f"part-{i:05d}.npz"


def _write_index(folder, sizes, names):
    """Write ``index.json`` of a shard folder (``sizes``: points per shard, in order)."""
    folder = Path(folder)
    idx = {"format": SHARDS_FORMAT, "n": int(sum(sizes)), "arrays": list(names),
           "shards": [{"file": _shard_name(i), "n": int(m)} for i, m in enumerate(sizes)]}
    text = json.dumps(idx, indent=1) + "\n"
    _replace_when_written(folder / "index.json", lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def _shard_index(folder):
    """The parsed ``index.json`` of a shard folder, checked (names the folder and the field)."""
    folder = Path(folder)
    try:
        idx = json.loads((folder / "index.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise CCProofError(f"{folder}: not a shard folder (index.json: {exc})") from None
    if not isinstance(idx, dict) or idx.get("format") != SHARDS_FORMAT:
        raise CCProofError(f"{folder}/index.json: field 'format' must be {SHARDS_FORMAT!r}")
    for j, s in enumerate(idx.get("shards", [])):
        if not isinstance(s, dict) or not isinstance(s.get("n"), int) or not isinstance(s.get("file"), str):
            raise CCProofError(f"{folder}/index.json: shards[{j}] needs 'file' (str) and 'n' (int)")
        if not (folder / s["file"]).is_file():
            raise CCProofError(f"{folder}: shard {s['file']} listed in index.json is missing")
    return idx


def write_shards(folder, arrays):
    """Write a dict of equally chunked dask (or numpy) arrays of length n as a shard folder.

    Each chunk of the first array's chunking becomes one ``part-NNNNN.npz``, with an ``index.json``
    (docs/scale-out.md, "Chunked evaluation").

    Parameters
    ----------
    folder : str or pathlib.Path
        Created if missing.
    arrays : dict of str -> dask or numpy array, shape (n, ...)
        Equally long arrays; numpy arrays are one shard.

    Returns
    -------
    pathlib.Path
        ``folder``.

    Examples
    --------
    >>> import tempfile, numpy as np, dask.array as da
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> d = write_shards(tmp.name, {"x": da.arange(5, chunks=2)})
    >>> sorted(p.name for p in d.iterdir())
    ['index.json', 'part-00000.npz', 'part-00001.npz', 'part-00002.npz']
    >>> read_shards(d)["x"].compute().tolist()
    [0, 1, 2, 3, 4]
    """
    import dask
    import dask.array as da
    import numpy as np

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    names = list(arrays)
    first = da.asarray(arrays[names[0]])
    chunks = first.chunks[0]
    arrs = {n: da.asarray(a).rechunk({0: chunks}) for n, a in arrays.items()}

    def save(path, *blocks):
        np.savez(path, **dict(zip(names, blocks)))
        return blocks[0].shape[0]

    writes = [dask.delayed(save)(str(folder / _shard_name(i)), *[arrs[n].blocks[i] for n in names])
              for i in range(len(chunks))]
    sizes = dask.compute(*writes)
    _write_index(folder, sizes, names)
    return folder


def read_shards(folder):
    """The arrays of a shard folder (:func:`write_shards`) as dask arrays, one chunk per shard.

    Parameters
    ----------
    folder : str or pathlib.Path
        A shard folder with its ``index.json``.

    Returns
    -------
    dict of str -> dask array, shape (n, ...)

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> d = write_shards(tmp.name, {"u": np.array([0.25, 0.5])})
    >>> x = read_shards(d)["u"]
    >>> x.chunks, x.compute().tolist()
    (((2,),), [0.25, 0.5])
    """
    import dask
    import dask.array as da
    import numpy as np

    folder = Path(folder)
    idx = _shard_index(folder)
    names = idx["arrays"]
    with np.load(folder / idx["shards"][0]["file"]) as z:
        protos = {n: z[n] for n in names}

    def load(path, name):
        with np.load(path) as z:
            return z[name]

    out = {}
    for n in names:
        parts = [da.from_delayed(dask.delayed(load)(str(folder / s["file"]), n),
                                 shape=(s["n"], *protos[n].shape[1:]), dtype=protos[n].dtype)
                 for s in idx["shards"]]
        out[n] = da.concatenate(parts) if parts else da.from_array(protos[n][:0])
    return out


def point_chunks(chunk, *, arrays=None, shards=None, samples=None, seed=0, n_faces=None):
    """Chunk sources for ``ccproof eval``: from arrays (face, u, v), a shard folder, or random samples.

    ``samples`` random points are drawn chunk by chunk (chunk i from its own seeded generator, so the
    points do not depend on the scheduler); docs/scale-out.md.

    Parameters
    ----------
    chunk : int
        Points per chunk, >= 1.
    arrays : tuple of three arrays, shape (n,), optional
        ``(face, u, v)`` in memory.
    shards : str or pathlib.Path, optional
        A shard folder holding face, u, v.
    samples : int, optional
        Number of random points (needs ``n_faces``).
    seed : int, optional
    n_faces : int or array of int, optional
        Faces ``0 .. n_faces - 1``, or the ids of the faces to draw from (e.g. all but the holes).

    Returns
    -------
    list of tuple
        One source per chunk: ``("arrays", face, u, v)``, ``("shard", path)`` or
        ``("samples", seed, n_faces, count, index)``.

    Examples
    --------
    >>> import numpy as np
    >>> src = point_chunks(2, arrays=(np.array([0, 1, 2]), np.zeros(3), np.ones(3)))
    >>> [(s[0], s[1].tolist()) for s in src]
    [('arrays', [0, 1]), ('arrays', [2])]
    >>> [s[3] for s in point_chunks(4, samples=10, n_faces=6)]
    [4, 4, 2]
    """
    if chunk < 1:
        raise CCProofError(f"--chunk must be >= 1, got {chunk}")
    if shards is not None:
        idx = _shard_index(shards)
        # absolute: a worker of a cluster may run in another folder
        return [("shard", str(Path(shards).resolve() / s["file"])) for s in idx["shards"]]
    if arrays is not None:
        f, u, v = arrays
        n = len(f)
        return [("arrays", f[a:a + chunk], u[a:a + chunk], v[a:a + chunk]) for a in range(0, max(n, 1), chunk)]
    if samples is None or samples < 0:
        raise CCProofError(f"--samples must be >= 0, got {samples}")
    return [("samples", seed, n_faces, min(chunk, samples - a), i)
            for i, a in enumerate(range(0, max(samples, 1), chunk))]


def evaluate_points(shipped, sources, derivatives, kwargs, out, scheduler=None, *, local=None, progress=True):
    """Evaluate every chunk (one task each, see :func:`ccproof.scale.engine.run_tasks`) and write ``out``.

    ``out`` ending in ``.npz`` gathers all points into one file (arrays face, u, v, P, ...); any other
    path is a shard folder (one ``part-NNNNN.npz`` per chunk, written by the worker, and ``index.json``),
    for point sets that do not fit in memory (docs/scale-out.md); ``ccproof eval`` passes only ``.npz``
    names or folders asked for. Every file is written under a temporary name and renamed when complete.

    Parameters
    ----------
    shipped : Shipped
        ``ship(limit_surface, mesh, ...)``.
    sources : list
        Chunk sources of :func:`point_chunks`.
    derivatives : {0, 1, 2}
    kwargs : dict
        Passed to the surface's ``evaluate``.
    out : str or pathlib.Path
        A ``.npz`` file or a shard folder.
    scheduler : str or Scheduler or distributed.Client, optional
        See :func:`ccproof.scale.engine.parse_scheduler`.
    local : object, optional
        The surface already built in this process (used by in-process tasks instead of a rebuild).
    progress : bool, optional

    Returns
    -------
    n : int
        Number of points.
    names : tuple of str
        Result names (:func:`output_names`).
    sweep : Sweep
        Its ``seconds``: the wall-clock time of the tasks (not the gathering and writing of ``out``).
    setup_seconds : float
        The longest time a task spent building the surface (each worker process builds it once, the workers at
        the same time; 0 when ``local`` served every task). ``sweep.seconds - setup_seconds`` is the evaluation's.

    Examples
    --------
    >>> import os, tempfile, numpy as np
    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.reparam.surface import limit_surface
    >>> from ccproof.scale import ship
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> out = os.path.join(tmp.name, "p.npz")
    >>> src = point_chunks(1, arrays=(np.array([0, 0]), np.array([0.5, 0.5]), np.array([0.5, 0.5])))
    >>> evaluate_points(ship(limit_surface, cube()), src, 0, {}, out, "serial", progress=False)[:2]
    (2, ('P',))
    >>> evaluate_points(ship(limit_surface, cube()), src, 0, {}, out, "serial", progress=False)[3] < 1  # built
    True
    >>> P = np.load(out)["P"]
    >>> bool(np.all(np.abs(np.abs(P[:, 2]) - 68 / 81) < 1e-12))
    True
    """
    from .engine import run_tasks

    if local is not None:
        rebuild(shipped, local=local)
    names = output_names(derivatives)
    folder = None if str(out).endswith(".npz") else Path(out).resolve()  # absolute: workers may run elsewhere
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    tasks = [{"source": s, "derivatives": derivatives, "kwargs": dict(kwargs),
              "out": None if folder is None else str(folder / _shard_name(i))} for i, s in enumerate(sources)]
    sweep = run_tasks(_evaluate_chunk, tasks, scheduler, shared=[shipped], desc="evaluate", unit="chunk",
                      progress=progress, names=[f"chunk {i}" for i in range(len(tasks))])
    n, counts, seconds = _gather(sweep.results, names, out, folder, progress)
    _warn_degenerate(n, counts)
    return n, names, sweep, max((s[0] for s in seconds), default=0.0)


def _gather(results, names, out, folder, progress=False):
    """(points, degenerate-normal counts, seconds per chunk) of the chunks' ``results``: written to the file
    ``out`` (one .npz) when ``folder`` is None, else the shards' index written in ``folder``. The chunks'
    arrays are taken out of ``results`` one name at a time (each freed once joined; a single chunk's arrays
    are not copied); ``progress``: a bar of the arrays joined and the file written."""
    import numpy as np

    if folder is None:
        keys = ("face", "u", "v", *names)
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=len(keys) + 1, desc=f"write {Path(out).name}", unit="array")
        arrays = {}
        for n in keys:
            parts = [r.pop(n) for r in results]
            arrays[n] = parts[0] if len(parts) == 1 else np.concatenate(parts)
            del parts
            if bar is not None:
                bar.update(1)
        _replace_when_written(out, lambda tmp: np.savez(tmp, **arrays))
        if bar is not None:
            bar.update(1)
            bar.close()
        counts = [degenerate_normals(arrays)]
        return int(arrays["face"].size), counts, [r["seconds"] for r in results]
    _write_index(folder, [r[0] for r in results], ("face", "u", "v", *names))
    return int(sum(r[0] for r in results)), [r[1] for r in results], [r[2] for r in results]
