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
import re
import time
import uuid
from pathlib import Path

from ccproof.errors import CCProofError
from ccproof.scale.processes import pid_alive

__all__ = ["check_file", "check_folder", "check_outputs", "atomic", "write_text", "is_folder_request",
           "meshio_suffixes", "PLOT_SUFFIXES", "OutputPlan"]

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
    format by the suffix, numpy, meshio, matplotlib, write the same format), with the writer's process id
    (a later run removes those of dead writers, :func:`remove_stale_temporaries`)."""
    return path.with_name(f".tmp-{os.getpid()}-{uuid.uuid4().hex[:6]}-{path.name}")


#: the longest temporary name beyond the final name (``.tmp-PID-hhhhhh-``; Linux pids have at most 7 digits)
TEMPORARY_EXTRA = len(".tmp-") + 7 + 1 + 6 + 1
_TEMPORARY = re.compile(r"^\.tmp-(?:(\d+)-[0-9a-f]{6}|[0-9a-f]{8})-(.+)$")  # ours, and older versions' (no pid)
#: a temporary file of an older version (no pid in its name) is stale after this many seconds
STALE_SECONDS = 3600.0


def remove_stale_temporaries(path) -> int:
    """Remove the temporary files of ``path`` (:func:`_temporary`; for a folder, those in it) left by a killed
    writer (its process is gone, or, for an older version's name without a pid, older than
    :data:`STALE_SECONDS`); returns how many. Temporary files of running writers and every other file are
    kept."""
    path = Path(path)
    inside = path.is_dir()  # an output folder (shards): every temporary file of ours in it
    folder = path if inside else path.parent
    n = 0
    try:
        names = os.listdir(folder)
    except OSError:
        return 0
    for name in names:
        m = _TEMPORARY.match(name)
        if m is None or not inside and m.group(2) != path.name:
            continue
        q = folder / name
        try:
            stale = not pid_alive(int(m.group(1))) if m.group(1) else time.time() - q.stat().st_mtime > STALE_SECONDS
            if stale:
                q.unlink()
                n += 1
        except OSError:
            pass
    return n


@contextlib.contextmanager
def _named(path, tmp):
    """An OSError of a writer (a full disk) that names no file, or the temporary one, names ``path``."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None or os.fspath(exc.filename) == os.fspath(tmp):
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise


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
        with _named(path, tmp):
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


def _identity(p: Path):
    """What a path names: the file's (device, inode) when it exists, else its resolved path (symbolic links
    and ``..`` followed), so that two spellings of one file, a link to it, or a hard link compare equal."""
    try:
        st = os.stat(p)
        return ("inode", st.st_dev, st.st_ino)
    except OSError:
        return ("path", os.path.realpath(p))


def _name_limits(p: Path, what: str):
    """Refuse a name (or its temporary name) beyond the file system's limits, before any work."""
    folder = p.parent if p.parent.exists() else Path(os.path.abspath(os.sep))
    try:
        name_max = os.pathconf(folder, "PC_NAME_MAX")
        path_max = os.pathconf(folder, "PC_PATH_MAX")
    except (OSError, ValueError, AttributeError):
        name_max, path_max = 255, 4096
    n = len(os.fsencode(p.name))
    if n + TEMPORARY_EXTRA > name_max:
        raise CCProofError(f"{what}: the name is {n} bytes long; this file system allows {name_max}, and the "
                           f"temporary name it is written under first {TEMPORARY_EXTRA} more: use at most "
                           f"{name_max - TEMPORARY_EXTRA} bytes")
    if len(os.fsencode(str(p))) + TEMPORARY_EXTRA >= path_max:
        raise CCProofError(f"{what}: the path is longer than this file system allows ({path_max} bytes)")


class OutputPlan:
    """Every file one run of a command writes, checked together before any work; written all or none.

    :meth:`add` checks each output as :func:`check_file` does, and its name (and the temporary name it is
    written under) against the file system's limits; :meth:`add_input` records an input; :meth:`check`
    then refuses two outputs naming one file, or an output naming an input (resolved: another spelling,
    a symbolic or a hard link), and removes the temporary files of these names left by a killed run.
    Files are written to temporary names (:meth:`write`, :meth:`adopt`) and renamed onto their names only
    when the whole run succeeded (:meth:`commit`, at the end of the ``with`` block); on any failure every
    temporary file is removed, so nothing of the run is left under any of its names.

    Examples
    --------
    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> a = os.path.join(tmp.name, "a.obj")
    >>> plan = OutputPlan()
    >>> _ = plan.add("--out", a, (".obj",)); _ = plan.add("--surface-out", tmp.name + "/./a.obj", (".obj",))
    >>> plan.check()
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --surface-out .../a.obj and --out .../a.obj name the same file: one would ...
    >>> plan = OutputPlan(); out = plan.add("--out", a, (".obj",)); plan.check()
    >>> with plan:
    ...     with plan.write(out) as part, open(part, "w") as fh:
    ...         _ = fh.write("v 0 0 0")
    >>> os.listdir(tmp.name)
    ['a.obj']
    """

    def __init__(self):
        self.outputs = []  # (option text, absolute path)
        self.inputs = []
        self._pending = []  # (temporary, final)

    def add(self, option, path, suffixes=(), *, hint="") -> Path:
        """Check the output ``path`` of ``option`` (:func:`check_file`, name limits); returns it absolute."""
        p = check_file(path, suffixes, option, hint=hint)
        _name_limits(p, f"{option} {path}")
        self.outputs.append((f"{option} {path}", p))
        return p

    def add_folder(self, option, path) -> Path:
        """Check the output folder ``path`` of ``option`` (:func:`check_folder`); returns it absolute."""
        p = check_folder(path, option)
        self.outputs.append((f"{option} {path}", p))
        return p

    def add_input(self, option, path):
        """Record an input file (``option``: how messages name it) that no output may replace."""
        if path is not None:
            self.inputs.append((f"{option} {path}".strip(), Path(os.path.abspath(os.fspath(path)))))

    def check(self):
        """Refuse outputs naming one file, or an input; remove stale temporary files of the outputs."""
        seen = {}
        for what, p in self.inputs:
            seen.setdefault(_identity(p), (what, True))
        for what, p in self.outputs:
            key = _identity(p)
            if key in seen:
                other, is_input = seen[key]
                raise CCProofError(f"{what} and {other} name the same file: " + (
                    "an output would replace an input" if is_input else "one would replace the other"))
            seen[key] = (what, False)
        for _, p in self.outputs:
            remove_stale_temporaries(p)

    @contextlib.contextmanager
    def write(self, path):
        """Yield a temporary path for the output ``path``; it is renamed onto ``path`` at :meth:`commit`."""
        path = Path(path)
        tmp = _temporary(path)
        self._pending.append((tmp, path))
        with _named(path, tmp):
            yield str(tmp)
        if not tmp.exists():
            raise CCProofError(f"{path}: the writer produced no file")

    def adopt(self, tmp, path):
        """A file a writer made next to a temporary one (a sidecar), to be renamed onto ``path`` too."""
        self._pending.append((Path(tmp), Path(path)))

    def write_text(self, path, text, encoding="utf-8"):
        with self.write(path) as tmp, open(tmp, "w", encoding=encoding) as fh:
            fh.write(text)

    def commit(self):
        for tmp, path in self._pending:
            os.replace(tmp, path)
        self._pending = []

    def abort(self):
        for tmp, _ in self._pending:
            with contextlib.suppress(OSError):
                tmp.unlink()
        self._pending = []

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            try:
                self.commit()
            except BaseException:
                self.abort()
                raise
        else:
            self.abort()
        return False
