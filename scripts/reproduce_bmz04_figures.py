"""Reproduce bmz04 Figures 2, 4, 5 (isoparameter lines near extraordinary vertices in the natural,
vanishing-derivative and characteristic-map parameterizations) and Figure 7 (|dP/du| along the
diagonal towards an extraordinary vertex, log scale).

Meshes: the planar k-regular disks of bmz04 section 3 (``ccproof.mesh.examples.k_regular_disk``,
3 rings), vertex 0 of valence k at the origin. Writes PNG files (matplotlib, Agg) into --out and
prints the measured rates of Figure 7 (log2 of the ratio of |dP/du| between consecutive halvings
of the distance, against log2(2 lam) for the natural parameterization).

Usage:
  python scripts/reproduce_bmz04_figures.py [--out figures/bmz04] [--lines 16]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

FIG_VALENCES = (3, 5, 7, 13)
PARAMS = (("natural", "Fig. 2: natural parameterization"),
          ("vanishing", "Fig. 4: vanishing derivatives (F^alpha blend, section 4.2)"),
          ("characteristic", "Fig. 5: characteristic map (Phi^-1 blend, section 4.3)"))


def isoline_figure(path, param, title, n_lines):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ccproof.mesh.examples import k_regular_disk
    from ccproof.reparam import limit_surface
    from ccproof.reparam.plot import isoparameter_lines

    fig, axes = plt.subplots(2, len(FIG_VALENCES), figsize=(4 * len(FIG_VALENCES), 8.3), dpi=130)
    for col, k in enumerate(FIG_VALENCES):
        S = limit_surface(k_regular_disk(k, rings=3))
        lines, is_edge = isoparameter_lines(S, 0, param, n_lines=n_lines, n_samples=401)
        for row, zoom in enumerate((None, 0.3)):
            ax = axes[row, col]
            for P, edge in zip(lines, is_edge):
                ax.plot(P[:, 0], P[:, 1], color="k" if edge else "tab:blue", lw=0.9 if edge else 0.35)
            ax.plot([0], [0], "o", color="tab:red", ms=3)
            ax.set_aspect("equal")
            ax.set_axis_off()
            if zoom:
                ax.set_xlim(-zoom, zoom)
                ax.set_ylim(-zoom, zoom)
                ax.set_title(f"k = {k}, zoom on the vertex", fontsize=10)
            else:
                ax.set_title(f"k = {k}", fontsize=10)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def derivative_profiles(m_max=40):
    """|dP/du| at t = 2^-m (1, 1) on face 0 of the k-regular disk, k = 3..13, three parameterizations."""
    from ccproof.mesh.examples import k_regular_disk
    from ccproof.reparam import limit_surface

    m = np.arange(1, m_max + 1)
    d = 2.0**-m
    out = {}
    for k in range(3, 14):
        S = limit_surface(k_regular_disk(k, rings=3))
        for p, _ in PARAMS:
            r = S.evaluate(np.zeros(m.size, dtype=np.int64), d, d, parameterization=p)
            out[(k, p)] = np.linalg.norm(r["Pu"], axis=1)
    return m, out


def fig7(path, m, prof):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), dpi=130, sharey=True)
    cmap = plt.get_cmap("viridis")
    for ax, (p, title) in zip(axes, PARAMS):
        for k in range(3, 14):
            y = prof[(k, p)]
            ok = y > 0
            ax.semilogy(m[ok], y[ok], color=cmap((k - 3) / 10), lw=1.2, label=f"k={k}")
        ax.set_xlabel("m  (point 2^-m (1, 1), towards the extraordinary vertex)")
        ax.set_title(title.split(": ", 1)[1], fontsize=10)
        ax.grid(True, which="both", lw=0.3)
    axes[0].set_ylabel("|dP/du|")
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("Fig. 7: magnitude of the derivative near extraordinary vertices", fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="figures/bmz04", help="output folder (default figures/bmz04)")
    ap.add_argument("--lines", type=int, default=32, help="isoparameter lines per direction and face")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    names = {"natural": "fig2_natural.png", "vanishing": "fig4_vanishing.png",
             "characteristic": "fig5_characteristic.png"}
    for p, title in PARAMS:
        isoline_figure(out / names[p], p, title, args.lines)
        print(f"wrote {out / names[p]}")
    m, prof = derivative_profiles()
    fig7(out / "fig7_derivatives.png", m, prof)
    print(f"wrote {out / 'fig7_derivatives.png'}")
    from ccproof.reparam.quadrant import subdominant_lambda

    print("\nFig. 7 rates: median of log2(|dP/du|(m+1) / |dP/du|(m)) over m = 12..28 (0 values left out:")
    print("the vanishing derivative is returned as 0 beyond the deepest layer the evaluator stores)")
    print(" k   natural  log2(2 lam)  vanishing  characteristic  |dP/du| char. at m=40")
    sel = (m >= 12) & (m <= 28)

    def rate(y):
        y = y[sel]
        y = y[y > 0]
        return float(np.median(np.diff(np.log2(y)))) if y.size > 1 else float("nan")

    for k in range(3, 14):
        rates = {p: rate(prof[(k, p)]) for p, _ in PARAMS}
        print(f"{k:2d}  {rates['natural']:8.4f}  {math.log2(2 * subdominant_lambda(k)):11.4f}  "
              f"{rates['vanishing']:9.4f}  {rates['characteristic']:14.2e}  {prof[(k, 'characteristic')][-1]:10.4f}")


if __name__ == "__main__":
    main()
