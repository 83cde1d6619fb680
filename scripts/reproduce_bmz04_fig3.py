"""Reproduce bmz04 Figure 3: layers and polynomial pieces of the characteristic map, k = 3, 5, 8.

For each valence, right: the face [0,1]^2 (the natural parameter, extraordinary vertex at the
origin) with the pieces D^l_j of layers l = 0..3 (the rest, layers >= 4, in grey); left: the image
under the characteristic map. The image is rasterized by *inverting* Phi at every pixel
(:func:`ccproof.inverse.inverse_characteristic_map`, which reports the layer and piece of each
point), and the black curves are the zero sets g = 0 of the implicit cubics of the boundaries
(:mod:`ccproof.inverse.implicit`, bmz04 Definition 5), scaled to each layer with the relation
Phi(y/2) = lam Phi(y), drawn only next to the pieces they bound. The dashed white curves are the
parametric images of the domain boundaries: they coincide with the implicit curves.

Usage: ``python scripts/reproduce_bmz04_fig3.py [--out fig3.png] [--k 3 5 8] [--pixels 500]``
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def piece_colors():
    base = np.array([[0.95, 0.55, 0.35], [0.45, 0.70, 0.95], [0.55, 0.85, 0.45]])
    out = {}
    for layer in range(4):
        shade = 1.0 - 0.16 * layer
        for j in range(3):
            out[(layer, j)] = np.clip(base[j] * shade + (1 - shade) * 0.15, 0, 1)
    return out


def draw(ax_img, ax_dom, k, pixels):
    from matplotlib.patches import Rectangle

    from ccproof.algebra.specialize import subdominant_eigenvalue
    from ccproof.inverse import characteristic_map, inverse_characteristic_map
    from ccproof.inverse.implicit import implicit_polynomial

    lam = subdominant_eigenvalue(k, "float")
    colors = piece_colors()
    grey = np.array([0.8, 0.8, 0.8])
    # extent of the image of the face
    w = np.linspace(0, 1, 200)
    bx, by = characteristic_map(k, np.r_[np.ones_like(w), w], np.r_[w, np.ones_like(w)])
    ext = 1.05 * max(bx.max(), by.max())
    xs = np.linspace(0, ext, pixels)
    X, Y = np.meshgrid(xs, xs)
    res = inverse_characteristic_map(k, X, Y, full_output=True)
    inside = (res.r <= 1) & (res.s <= 1)
    img = np.ones(X.shape + (3,))
    for (layer, j), col in colors.items():
        img[(res.layer == layer) & (res.patch == j) & inside] = col
    img[(res.layer >= 4) & inside] = grey
    ax_img.imshow(img, origin="lower", extent=(0, ext, 0, ext), interpolation="nearest")

    # implicit boundaries: Gamma (inner boundary of layer 0, edge s = 0 of P1) scaled by lam^l bounds
    # layers l and l + 1; the outer boundary of the face is Gamma / lam; separators C (P1 | P2) and
    # its mirror (P2 | P3) inside each layer. Mirror images via g(v, u) for the upper half.
    def g_at(name, x, y):
        g = implicit_polynomial(k, name, "float")
        return sum(c * x**a * y**b for (a, b), c in g.items())

    for layer in range(-1, 4):
        s = lam ** -layer
        # layer boundaries: Gamma at layer `layer` separates layers layer and layer + 1
        for name, half in (("P1:s=0", X >= Y), ("P3:t=0", X <= Y)):
            G = g_at(name, X * s, Y * s)
            near = ((res.layer == layer) | (res.layer == layer + 1)) & half
            if layer == -1:
                near = ((res.layer == 0) | (res.layer == -1)) & half
            ax_img.contour(X, Y, np.ma.masked_where(~near, G), levels=[0], colors="k", linewidths=1.0)
        if layer >= 0:
            for name, half in (("P1:t=1", X >= Y), ("P2:s=0", X <= Y)):
                G = g_at(name, X * s, Y * s)
                near = (res.layer == layer) & half
                ax_img.contour(X, Y, np.ma.masked_where(~near, G), levels=[0], colors="k", linewidths=1.0)
    # parametric images of the domain lines (dashed white)
    for layer in range(4):
        h = 0.5**layer
        t = np.linspace(0, 1, 100)
        one, half = np.ones_like(t), 0.5 * np.ones_like(t)
        for u, v in ((h * one, h * t), (h * t, h * one), (h * (0.5 + 0.5 * t), h * half),
                     (h * half, h * (0.5 + 0.5 * t))):
            px, py = characteristic_map(k, u, v)
            ax_img.plot(px, py, "w--", lw=0.6)
    ax_img.set_xlim(0, ext)
    ax_img.set_ylim(0, ext)
    ax_img.set_aspect("equal")
    ax_img.set_title(f"k = {k}: image under Phi (lam = {lam:.4f})", fontsize=9)

    # domain
    for layer in range(4):
        h = 0.5**layer
        rects = {0: (h / 2, 0, h / 2, h / 2), 1: (h / 2, h / 2, h / 2, h / 2), 2: (0, h / 2, h / 2, h / 2)}
        for j, (x0, y0, wd, ht) in rects.items():
            ax_dom.add_patch(Rectangle((x0, y0), wd, ht, facecolor=colors[(layer, j)], edgecolor="k", lw=0.8))
            if layer <= 1:
                ax_dom.text(x0 + wd / 2, y0 + ht / 2, f"D{layer}{j + 1}", ha="center", va="center", fontsize=8)
    ax_dom.add_patch(Rectangle((0, 0), 1 / 16, 1 / 16, facecolor=grey, edgecolor="k", lw=0.8))
    ax_dom.set_xlim(0, 1)
    ax_dom.set_ylim(0, 1)
    ax_dom.set_aspect("equal")
    ax_dom.set_title("domain (r, s): layers 0-3, pieces Dlj", fontsize=9)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="bmz04_fig3.png")
    ap.add_argument("--k", type=int, nargs="*", default=[3, 5, 8])
    ap.add_argument("--pixels", type=int, default=500)
    args = ap.parse_args(argv)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(args.k), 2, figsize=(8, 4 * len(args.k)), squeeze=False)
    for row, k in enumerate(args.k):
        draw(axes[row][0], axes[row][1], k, args.pixels)
    fig.suptitle("bmz04 Fig. 3: layers and patches of the characteristic map (implicit boundaries in black)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
