"""The boundary edges of the layer pieces of the characteristic map (bmz04 section 4.3): every boundary
between two layers or between two of the pieces P1, P2, P3 is an edge of a bicubic Bezier net, named
``"P1:s=1"`` (the edge s = 1 of piece P1) and so on; :data:`EDGES` lists them with the segment and the piece
or layer across, :func:`get_edge` reads a name.
"""

from __future__ import annotations

from dataclasses import dataclass

from ccproof.errors import CCProofError

__all__ = ["Edge", "EDGES", "get_edge"]


#: the patch each net row/column belongs to, which local coordinate is fixed and its value
_EDGE_SPECS = {
    # name: (patch, axis (0: s fixed, 1: t fixed), value, face segment, the other side)
    "P1:s=0": ("P1", 0, 0, "u = 1/2, 0 <= v <= 1/2", "layer 1 (pieces P1, P2 of layer 1)"),
    "P1:s=1": ("P1", 0, 1, "u = 1, 0 <= v <= 1/2", "layer -1 (outside the face)"),
    "P1:t=1": ("P1", 1, 1, "v = 1/2, 1/2 <= u <= 1", "P2"),
    "P2:s=0": ("P2", 0, 0, "u = 1/2, 1/2 <= v <= 1", "P3"),
    "P2:s=1": ("P2", 0, 1, "u = 1, 1/2 <= v <= 1", "layer -1 (outside the face)"),
    "P2:t=0": ("P2", 1, 0, "v = 1/2, 1/2 <= u <= 1", "P1"),
    "P2:t=1": ("P2", 1, 1, "v = 1, 1/2 <= u <= 1", "layer -1 (outside the face)"),
    "P3:s=1": ("P3", 0, 1, "u = 1/2, 1/2 <= v <= 1", "P2"),
    "P3:t=0": ("P3", 1, 0, "v = 1/2, 0 <= u <= 1/2", "layer 1 (pieces P2, P3 of layer 1)"),
    "P3:t=1": ("P3", 1, 1, "v = 1, 0 <= u <= 1/2", "layer -1 (outside the face)"),
}


@dataclass(frozen=True)
class Edge:
    """A boundary edge of a layer-0 piece (bmz04 Definition 5; docs/inverse.md).

    Parameters
    ----------
    name : str
        ``"<patch>:<s|t>=<0|1>"``, the key of :data:`EDGES`.
    patch : str
        ``"P1"``, ``"P2"`` or ``"P3"``.
    axis : int
        The local coordinate held fixed (0: s, 1: t).
    value : int
        Its value (0 or 1).
    segment : str
        The face segment the edge is the image of.
    other : str
        The piece or layer across it.

    Examples
    --------
    >>> e = EDGES["P1:s=1"]
    >>> e.patch, e.axis, e.value, e.segment
    ('P1', 0, 1, 'u = 1, 0 <= v <= 1/2')
    """

    name: str
    patch: str
    axis: int
    value: int
    segment: str
    other: str

    def control_points(self, net):
        """The four Bezier control points of the edge, in the order of the free coordinate w."""
        a = 3 * self.value
        if self.axis == 0:
            return [net[a][j] for j in range(4)]
        return [net[i][a] for i in range(4)]

    def parameter(self, w, n=0):
        """Local (s, t) of the point at edge parameter w moved by n towards the piece's inside."""
        fixed = self.value - n if self.value == 1 else self.value + n
        return (fixed, w) if self.axis == 0 else (w, fixed)


#: every boundary edge, by name (``"P1:s=1"`` is the edge s = 1 of piece P1, ...)
EDGES = {name: Edge(name, *spec) for name, spec in _EDGE_SPECS.items()}


def get_edge(edge):
    if isinstance(edge, Edge):
        return edge
    try:
        return EDGES[edge]
    except KeyError:
        raise CCProofError(f"unknown boundary edge {edge!r}; choose one of {', '.join(EDGES)}") from None

