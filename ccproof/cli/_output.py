"""Output paths of the command line: checked before any computation, written atomically.

Every command that writes a file checks its path first (:func:`check_file`, :func:`check_folder`):
the folder must exist and be writable, the path must not be a folder, and its suffix must be one the
command can write (else the error lists the suffixes). A file is then written to a hidden temporary
name in the same folder and renamed onto the final name only when it is complete (:func:`atomic`), so
an error, Ctrl-C, SIGTERM or even SIGKILL during the write never leaves a partial file under the
final name (a rename within one folder is atomic on POSIX and Windows).

Examples
--------
>>> import os, tempfile
>>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
>>> out = check_file(os.path.join(tmp.name, "r.npz"), (".npz",))
>>> with atomic(out) as part:
...     with open(part, "w") as fh:
...         _ = fh.write("complete")
>>> os.listdir(tmp.name), open(out).read()
(['r.npz'], 'complete')
>>> check_file(os.path.join(tmp.name, "r.csv"), (".npz",))
Traceback (most recent call last):
...
ccproof.errors.CCProofError: --out ...r.csv: cannot write '.csv' files; use one of .npz
"""

from __future__ import annotations

import contextlib
import os
import uuid
from pathlib import Path

from ccproof.errors import CCProofError

__all__ = ["check_file", "check_folder", "check_outputs", "atomic", "write_text", "is_folder_request",
           "meshio_suffixes", "PLOT_SUFFIXES"]

#: what a plot option can write (matplotlib)
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def meshio_suffixes():
    """The suffixes meshio writes (``.vtu``, ``.ply``, ...), from the installed meshio."""
    import meshio

    return tuple(sorted(meshio.extension_to_filetypes))


def _writable_folder(folder: Path, what: str):
    if not folder.exists():
        raise CCProofError(f"{what}: folder {folder} does not exist")
    if not folder.is_dir():
        raise CCProofError(f"{what}: {folder} is not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise CCProofError(f"{what}: folder {folder} is not writable")


def _has_suffix(name: str, suffixes) -> bool:
    """Case-sensitive, as the writers are (numpy appends ``.npz`` to ``o.NPZ``)."""
    return any(name.endswith(s) and len(name) > len(s) for s in suffixes)


def check_file(path, suffixes, option="--out", *, hint="") -> Path:
    """Check an output file path before any work; returns it absolute.

    Parameters
    ----------
    path : str or os.PathLike
        The path as given on the command line.
    suffixes : sequence of str
        The suffixes the command can write (``(".npz",)``); empty: any.
    option : str
        The option's name for the message (``--out``).
    hint : str
        Appended to the list of suffixes (``"or FOLDER/ for shards"``).

    Returns
    -------
    pathlib.Path
        ``path`` made absolute (so that a worker of a cluster or a changed directory finds it).

    Raises
    ------
    CCProofError
        Naming the path when it is a folder, its folder is missing, not a folder or not writable, or
        its suffix is not one of ``suffixes`` (the message lists them).
    """
    p = Path(os.path.abspath(os.fspath(path)))
    what = f"{option} {path}"
    if str(path).endswith(("/", os.sep)) or p.is_dir():
        raise CCProofError(f"{what}: is a folder, not a file")
    if suffixes and not _has_suffix(p.name, suffixes):
        got = "".join(p.suffixes[-1:]) or "no suffix"
        got = f"{got!r} files" if got != "no suffix" else "a name without a suffix"
        raise CCProofError(f"{what}: cannot write {got}; use one of {', '.join(suffixes)}" + (hint and f" {hint}"))
    _writable_folder(p.parent, what)
    if p.exists() and not os.access(p, os.W_OK):
        raise CCProofError(f"{what}: the file exists and is not writable")
    return p


def check_outputs(args, **options):
    """Check the output files of parsed arguments before any work (:func:`check_file` each).

    Parameters
    ----------
    args : argparse.Namespace
    **options
        Attribute name -> the suffixes it may have: a tuple (empty: any), ``"mesh"`` (``.obj`` and every
        suffix meshio writes) or ``"plot"`` (:data:`PLOT_SUFFIXES`). Unset options are skipped; the
        option's name in messages is ``--name-with-dashes``.

    Examples
    --------
    >>> import argparse
    >>> check_outputs(argparse.Namespace(out="x.txt", preview=None), out=(".obj",), preview="plot")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --out x.txt: cannot write '.txt' files; use one of .obj
    """
    for name, suffixes in options.items():
        value = getattr(args, name, None)
        if value is None:
            continue
        if suffixes == "mesh":
            suffixes = (".obj", *(s for s in meshio_suffixes() if s != ".obj"))
        elif suffixes == "plot":
            suffixes = PLOT_SUFFIXES
        check_file(value, suffixes, "--" + name.replace("_", "-"))


def check_folder(path, option="--out", *, create=True) -> Path:
    """Check an output folder before any work; returns it absolute.

    The folder may exist (then it must be a writable folder) or, with ``create``, be created later:
    then its nearest existing ancestor must be a writable folder (never a file).

    Raises
    ------
    CCProofError
        Naming the path.
    """
    p = Path(os.path.abspath(os.fspath(path)))
    what = f"{option} {path}"
    if p.exists():
        if not p.is_dir():
            raise CCProofError(f"{what}: is a file, not a folder")
        _writable_folder(p, what)
        return p
    if not create:
        raise CCProofError(f"{what}: folder does not exist")
    anc = p.parent
    while not anc.exists() and anc != anc.parent:
        anc = anc.parent
    if not anc.is_dir():
        raise CCProofError(f"{what}: {anc} is a file, not a folder")
    _writable_folder(anc, what)
    return p


def is_folder_request(path) -> bool:
    """True when an ``--out`` asks for a folder: it ends with ``/``, is an existing folder, or has no
    suffix (``results``, ``shards/``); ``o.csv`` or ``o.npz`` name files.

    >>> [is_folder_request(p) for p in ("shards/", "shards", "o.npz", "o.csv")]
    [True, True, False, False]
    """
    text = os.fspath(path)
    return text.endswith(("/", os.sep)) or Path(text).is_dir() or not Path(text).suffix


def _temporary(path: Path) -> Path:
    """A hidden name in the same folder that keeps the full name at its end (so writers that choose a
    format by the suffix, numpy, meshio, matplotlib, write the same format)."""
    return path.with_name(f".tmp-{uuid.uuid4().hex[:8]}-{path.name}")


@contextlib.contextmanager
def atomic(path):
    """Yield a temporary path next to ``path``; rename it onto ``path`` when the block ends normally.

    On any exception (also ``KeyboardInterrupt``) the temporary file is removed and ``path`` is left as
    it was. A writer that appends its own suffix (``numpy.savez`` adds ``.npz``) gets a name that already
    ends with it.

    Yields
    ------
    str
    """
    path = Path(path)
    tmp = _temporary(path)
    try:
        yield str(tmp)
        if not tmp.exists():
            raise CCProofError(f"{path}: the writer produced no file")
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def write_text(path, text, encoding="utf-8"):
    """Write a text file atomically (:func:`atomic`)."""
    with atomic(path) as tmp, open(tmp, "w", encoding=encoding) as fh:
        fh.write(text)
