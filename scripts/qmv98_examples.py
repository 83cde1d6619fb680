"""qmv98 modelling examples (Fig. 6) and shape-recovery figures (Figs. 7-9) with ccproof.apps.dynamics.

  python scripts/qmv98_examples.py --out qmv98_figures           all modelling examples (Fig. 6)
  python scripts/qmv98_examples.py --out qmv98_figures --fit     plus the fits of the bulb and the bunny

Fig. 6 meshes (sizes from the paper): (a) open surface, 61 vertices, 45 faces, one valence-5 vertex; (b) torus,
32 / 32; (c) genus-2 surface, 542 / 544, eight valence-5 vertices; (d) flat sheet, 81 / 64. Springs are attached
from points in space to the nearest points of the limit surface (qmv98 section 4.1) and the model is evolved with
the implicit scheme (31) until equilibrium, with the initial shape as the rest shape (force ``K p0``). Every
example writes a before/after PNG (normal elements yellow, special elements green, anchors red);
``fig6_modelling.png`` collects them like the paper's Fig. 6.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ccproof.apps.dynamics.forces import Springs
from ccproof.apps.dynamics.integrate import ImplicitIntegrator
from ccproof.apps.dynamics.meshes import flat_sheet, genus2_surface, open_surface_valence5, torus_32
from ccproof.apps.dynamics.model import DynamicSurface, Material

MODEL_MATERIAL = Material(mu=1.0, gamma=2.0, a11=0.05, a22=0.05, b11=0.05, b12=0.1, b22=0.05)


def evolve(model, anchors, stiffness, dt=0.5, max_steps=600, tol=1e-6):
    """Attach springs to the nearest limit points of the initial surface and integrate (31) to equilibrium.

    The initial shape is the rest shape: the elastic force is ``-K (p - p0)``, i.e. the generalized force
    ``K p0`` is applied as well (without it eq. (17) pulls a closed surface towards its spring anchors).
    """
    P0 = model.vertices
    springs = Springs.to_nearest(model, P0, anchors, stiffness)
    rest = model.matvec(P0)
    integ = ImplicitIntegrator(model, dt, P=P0, scheme="inertial", tol=1e-9)
    for _ in range(max_steps):
        info = integ.step(force=rest, springs=springs)
        if info.displacement < tol * model.mesh.bounding_box_diagonal:
            break
    return integ.P, springs, len(integ.history)


def hat(n_side=5):
    model = DynamicSurface(flat_sheet(), MODEL_MATERIAL)
    g = np.linspace(-0.18, 0.18, n_side)
    cx, cy = np.meshgrid(g, g)
    crown = np.stack([cx.ravel(), cy.ravel(), np.full(cx.size, 0.9)], 1)
    th = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    brim = np.stack([0.6 * np.cos(th), 0.6 * np.sin(th), np.zeros_like(th)], 1)
    anchors = np.concatenate([crown, brim])
    k = np.r_[np.full(len(crown), 2.0), np.full(len(brim), 4.0)]
    return "(d) sheet -> hat", model, anchors, k


def torus():
    model = DynamicSurface(torus_32(), MODEL_MATERIAL)
    anchors = np.array([[3.9, 0.0, 0.0], [-2.0, 0.0, 1.6], [0.0, -2.0, -1.4]])
    return "(b) torus", model, anchors, np.array([3.0, 3.0, 3.0])


def open_surface():
    model = DynamicSurface(open_surface_valence5(), MODEL_MATERIAL)
    th = np.linspace(0, 2 * np.pi, 15, endpoint=False)
    ring = np.stack([0.45 * np.cos(th), 0.45 * np.sin(th), np.zeros_like(th)], 1)
    anchors = np.concatenate([[[0.0, 0.0, 0.6]], ring])
    k = np.r_[6.0, np.full(len(ring), 3.0)]
    return "(a) open surface, valence-5 vertex", model, anchors, k


def genus2():
    model = DynamicSurface(genus2_surface(), MODEL_MATERIAL)
    V = model.vertices
    top, bot, xo = V[:, 2].max(), V[:, 2].min(), V[:, 0].max()  # outer rims of the two tori at x = -+xo
    # upper part: stiff springs pulling up; lower part: weak springs pulling down (qmv98 section 4.1); all
    # anchored above / below the tubes (not the holes)
    c, R = 0.5 * xo, 0.32 * xo  # torus centres at x = -+xo/2, tube centre radius R (genus2_surface defaults)
    xy = np.array([[-c, R], [c, R], [-c - R, 0.0], [c + R, 0.0]])
    xy_low = np.array([[-c, -R], [c, -R], [-c - R, 0.0], [c + R, 0.0]])
    anchors = np.concatenate([np.c_[xy, np.full(4, top + 1.2)], np.c_[xy_low, np.full(4, bot - 1.2)]])
    k = np.r_[np.full(4, 2.0), np.full(4, 0.25)]
    return "(c) genus 2, 8 valence-5 vertices", model, anchors, k


EXAMPLES = {"open": open_surface, "torus": torus, "genus2": genus2, "hat": hat}


def draw_pair(fig, axes, title, model, P0, P1, springs):
    from ccproof.apps.dynamics.plot import draw_surface, set_equal_axes

    pts = []
    for ax, P, sub in ((axes[0], P0, "initial"), (axes[1], P1, "after springs")):
        pts.append(draw_surface(ax, model, P))
        ax.set_title(f"{title}\n{sub}", fontsize=8)
        A = springs.anchors
        ax.scatter(A[:, 0], A[:, 1], A[:, 2], color="red", s=6, depthshade=False)
        if sub != "initial":
            S = springs.jacobian @ P
            for a, s in zip(A, S):
                ax.plot(*np.stack([a, s], 1), color="red", lw=0.5)
        ax.view_init(elev=35, azim=-60)
    allp = np.concatenate(pts + [springs.anchors])
    for ax in axes:
        set_equal_axes(ax, allp)


def modelling(out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    big = plt.figure(figsize=(16, 8))
    rows = []
    for col, (name, make) in enumerate(EXAMPLES.items()):
        title, model, anchors, k = make()
        mesh = model.mesh
        t0 = time.perf_counter()
        P1, springs, steps = evolve(model, anchors, k)
        dt = time.perf_counter() - t0
        lay = model.layout
        rep = model.truncation_report(P1)
        rows.append((title, mesh.n_vertices, mesh.n_faces, mesh.extraordinary_vertices.size, lay.n_normal,
                     lay.n_special, steps, dt, rep))
        fig = plt.figure(figsize=(8, 4))
        draw_pair(fig, [fig.add_subplot(1, 2, 1, projection="3d"), fig.add_subplot(1, 2, 2, projection="3d")],
                  title, model, model.vertices, P1, springs)
        fig.tight_layout()
        fig.savefig(out / f"fig6_{name}.png", dpi=130)
        plt.close(fig)
        pair = [big.add_subplot(2, 4, 1 + col, projection="3d"), big.add_subplot(2, 4, 5 + col, projection="3d")]
        draw_pair(big, pair, title, model, model.vertices, P1, springs)
    big.tight_layout()
    big.savefig(out / "fig6_modelling.png", dpi=110)
    plt.close(big)
    print("Fig. 6 meshes and modelling runs (scheme (31), springs to nearest limit points):")
    print(f"{'example':36s} {'V':>5s} {'F':>5s} {'EVs':>4s} {'normal':>6s} {'special':>7s} {'steps':>5s} {'s':>6s}")
    for title, nv, nf, ne, nn, ns, steps, dt, rep in rows:
        print(f"{title:36s} {nv:5d} {nf:5d} {ne:4d} {nn:6d} {ns:7d} {steps:5d} {dt:6.2f}")
        for r in rep[:1]:
            rg = r["rigidity"]
            tail = "diverges" if not np.isfinite(rg["tail_estimate"]) else f"{rg['tail_estimate']:.2e}"
            print(f"    special element (valence {r['valence']}, L = {r['levels']}): rigidity energy "
                  f"{rg['truncated']:.3e}, level-L increment {rg['last_level']:.2e}, ratio 4 lam^2 = "
                  f"{rg['ratio']:.3f}, tail {tail}")


def fitting(out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ccproof.apps.dynamics.fit import fit_points, read_points
    from ccproof.apps.dynamics.model import DynamicSurface as DS
    from ccproof.apps.dynamics.plot import draw_surface, set_equal_axes
    from ccproof.apps.dynamics.shapes import synthetic_range_data

    bunny = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"
    cases = [("bulb (synthetic, 1,000 points)", synthetic_range_data("bulb"))]
    if bunny.exists():
        cases.append(("Stanford bunny (2,038 scanned vertices)", read_points(bunny)))
    for title, X in cases:
        snaps = {}

        def cb(level, step, model, P, snaps=snaps):
            if (level, step) in ((0, 1), (0, 4)):
                snaps[(level, step)] = (model, P.copy())

        t0 = time.perf_counter()
        res = fit_points(X, levels=1, callback=cb)
        dt = time.perf_counter() - t0
        print(f"{title}: " + ", ".join(f"{lev.n_vertices} vertices: max {lev.max_error_percent:.2f} %, mean "
                                       f"{lev.mean_error_percent:.3f} % ({lev.steps} steps)" for lev in res.levels)
              + f"; {dt:.1f} s")
        fig = plt.figure(figsize=(12, 4))
        Xn = (X - res.center) / res.diameter
        stages = [("initial model (98 vertices)", snaps[(0, 1)][0], snaps[(0, 1)][0].vertices),
                  ("after 4 steps", *snaps[(0, 4)]),
                  (f"fitted, {res.model.n_vertices} vertices, max error {res.max_error_percent:.2f} %",
                   res.model, res.normalized_state)]
        for i, (sub, model, P) in enumerate(stages):
            ax = fig.add_subplot(1, 3, i + 1, projection="3d")
            pts = draw_surface(ax, model, P, per_edge=4, alpha=0.85 if i else 0.6)
            ax.scatter(Xn[:, 0], Xn[:, 1], Xn[:, 2], s=0.3, color="black", depthshade=False)
            set_equal_axes(ax, np.concatenate([pts, Xn]))
            ax.set_title(sub, fontsize=8)
            ax.view_init(elev=15, azim=-70)
        fig.suptitle(title, fontsize=9)
        fig.tight_layout()
        name = "fit_bunny.png" if "bunny" in title else "fit_bulb.png"
        fig.savefig(out / name, dpi=130)
        plt.close(fig)
        assert isinstance(res.model, DS)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="qmv98_figures", help="output folder for the PNG figures")
    ap.add_argument("--fit", action="store_true", help="also the shape-recovery figures (bulb, bunny)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    modelling(out)
    if args.fit:
        fitting(out)
    print(f"figures in {out}/")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
