"""Isoparameter lines of the three parameterizations around a vertex (bmz04 Figs. 2, 4, 5).

Reuses :mod:`ccproof.evaluate.plot` through a view of the surface whose ``evaluate`` uses the
chosen parameterization. Matplotlib is imported inside the functions.
"""

from __future__ import annotations

__all__ = ["ParameterizedView", "isoparameter_lines", "plot_isoparameter_lines"]


class ParameterizedView:
    """A :class:`~ccproof.reparam.surface.ReparamLimitSurface` seen through one parameterization."""

    def __init__(self, surface, parameterization):
        self.surface = surface
        self.mesh = surface.mesh
        self.parameterization = parameterization

    def evaluate(self, face_ids, u, v, derivatives=1, **kw):
        return self.surface.evaluate(face_ids, u, v, derivatives, parameterization=self.parameterization, **kw)

    def vertex_limits(self):
        return self.surface.vertex_limits()

    def vertex_normals(self):
        return self.surface.vertex_normals()


def isoparameter_lines(surface, vertex, parameterization="natural", n_lines=16, n_samples=257):
    """:func:`ccproof.evaluate.plot.isoparameter_lines` in the given parameterization."""
    from ccproof.evaluate import plot

    return plot.isoparameter_lines(ParameterizedView(surface, parameterization), vertex, n_lines, n_samples)


def plot_isoparameter_lines(surface, vertex, path, parameterization="natural", n_lines=16, title=None):
    """:func:`ccproof.evaluate.plot.plot_isoparameter_lines` in the given parameterization."""
    from ccproof.evaluate import plot

    view = ParameterizedView(surface, parameterization)
    if title is None:
        k = int(surface.mesh.valence[vertex])
        title = f"{parameterization} parameterization near vertex {vertex} (valence {k})"
    plot.plot_isoparameter_lines(view, vertex, path, n_lines=n_lines, title=title)
