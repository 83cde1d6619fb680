#!/usr/bin/env python
"""``HalfEdges`` constructions of one ``ccproof arap`` or ``ccproof fit`` run, with the options of
tests/test_cli_topology_builds.py: how many, how many distinct topologies, how many built again.

``HalfEdges.__init__`` and ``HalfEdges.refined`` (where the tree has it: a refined mesh's topology derived
from its parent's) are wrapped (views are no constructions) and each construction's topology recorded (vertex
count, ``org``, ``offsets``). Run it with ``PYTHONPATH`` at the source tree to count (an old tree from
``git archive`` for the counts before a change).

Usage: python scripts/count_topology_builds.py {arap,fit} MESH
"""

import collections
import contextlib
import io
import os
import sys
import tempfile

import numpy as np


def main():
    from ccproof.mesh.halfedges import HalfEdges

    seen = []
    init = HalfEdges.__init__

    def counted(self, *a, **k):
        init(self, *a, **k)
        seen.append((self.n_vertices, np.asarray(self.org).tobytes(), np.asarray(self.offsets).tobytes()))

    HalfEdges.__init__ = counted
    if hasattr(HalfEdges, "refined"):  # a refined mesh's topology derived from its parent's: a construction too
        refined = HalfEdges.refined.__func__

        def counted_refined(cls, *a, **k):
            he = refined(cls, *a, **k)
            seen.append((he.n_vertices, np.asarray(he.org).tobytes(), np.asarray(he.offsets).tobytes()))
            return he

        HalfEdges.refined = classmethod(counted_refined)
    from ccproof.apps.dynamics.shapes import synthetic_range_data
    from ccproof.cli import main as cli

    cmd, mesh = sys.argv[1], sys.argv[2]
    d = tempfile.mkdtemp()
    if cmd == "fit":
        xyz = os.path.join(d, "s.xyz")
        np.savetxt(xyz, synthetic_range_data("bulb", 200, seed=1))
        argv = ["fit", xyz, "--init", mesh, "--levels", "0", "--max-steps", "2", "--out", os.path.join(d, "f.obj"),
                "--no-progress"]
    else:
        argv = ["arap", mesh, "--segment", "normals", "--levels", "1", "--eval-level", "2", "--refine", "0",
                "--out", os.path.join(d, "uv.obj"), "--allow-folds", "--no-progress"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert cli(argv) == 0
    c = collections.Counter(seen)
    print(cmd, os.path.basename(mesh), "constructions", len(seen), "topologies", len(c), "built again",
          len(seen) - len(c), "most builds of one", max(c.values()))


if __name__ == "__main__":
    main()
