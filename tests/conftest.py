"""Fixtures shared by every test folder: the reference data that ships with the repository (tests/data), and the
processes of a session (what a command leaves running)."""

import os
from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def refdir():
    """``tests/data``: OpenSubdiv reference values and the test meshes (see tests/data/README.md)."""
    return DATA


@pytest.fixture(scope="session")
def bunny_path():
    """The quad-remeshed Stanford bunny (2,038 vertices, 2,036 quads)."""
    return DATA / "meshes" / "bunny_quads.obj"


def _session_processes(sid, zombies=True):
    """The processes of session ``sid`` (from /proc), zombies counted unless ``zombies`` is False."""
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                stat = open(f"/proc/{d}/stat").read()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()  # (state, ppid, pgrp, session, ...)
            if int(fields[3]) == sid and (zombies or fields[0] != "Z"):
                out.append(int(d))
    return out


@pytest.fixture
def session_processes():
    """``session_processes(sid, zombies=True)``: the pids of a session's processes (a command started with
    ``start_new_session=True`` has its pid as session id), to check that none outlives it."""
    return _session_processes
