"""Table of every certified valence (N, certified margins, lam, verify time), re-derived in this run.

  ccproof report                 re-verify every injectivity certificate and print the table
  ccproof report --jobs 2        the same on 2 processes
  ccproof report --write         also write it as Markdown to docs/certified_valences.md
  ccproof report --plot F.png    plot the margins against k
  ccproof report --tagged        re-verify the tagged certificates (certificates/c1/{dart,crease,corner}/)
                                 and print configuration, statement, verdict and the spectral reason, then
                                 each family's coverage as the verifier decides it from those verdicts

Every number comes from the verifier's run (its VerifyResult): the smallest bound it re-checked per
part (det J_Phi and det J_G in the local coordinates of their boxes, det J_G / h^2 on the corner cell)
and lam as the verifier derives it. Nothing is read from a file's own fields, and a certificate that
fails is listed as FAILED without numbers.
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("--write", action="store_true", help="write docs/certified_valences.md")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default 1; >= 1, at most the cores of "
                   "this machine and the number of certificates)")
    p.add_argument("--plot", default=None, help="write a PNG plot of the margins against k")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(p)
    p.add_argument("--tagged", action="store_true",
                   help="the table of the tagged configurations (dart, crease, corner; docs/tagged_c1.md) instead")


def _row(path):
    import time

    from flint import arb, ctx

    from ccproof.certify.verify import verify_file
    from ccproof.certify.verify.statement import c_lam
    from ccproof.valence import Valence

    t = time.perf_counter()
    res = verify_file(path, log=lambda s: None)
    k = None if res.valence is None else Valence.parse(res.valence)  # None: the file has no readable valence
    row = {"k": k, "N": res.N, "ok": res.ok, "verify_s": round(time.perf_counter() - t, 1), "path": str(path)}
    if not res.ok:
        return row
    if k.interval:
        lam = f"[{c_lam(k.k, 64)[1].lower().str(7, radius=False)}, 0.654508]"
    else:
        with ctx.workprec(64):
            lam = arb(c_lam(k.k, 64)[1]).str(7, radius=False)
    m = res.margins
    row.update(lam=lam, detPhi=float(m["regularity"]) * 4,  # d(s,t)/d(u,v) = 4
               detG_cells=float(m["cells"]) * 4 ** res.N, detG_corner=float(m["corner"]))
    return row


def injectivity_files():
    """The injectivity certificates of the checkout (or of the installed package)."""
    from ccproof.certify.verify import certificate_files
    from ccproof.tables.format import certificates_dir

    return [p for p in certificate_files(certificates_dir()) if p.parent.name == "injectivity"]


def collect(jobs=1, progress=True):
    """One row per injectivity certificate, each from a fresh verifier run (a progress bar when ``progress``
    and ``jobs`` is 1)."""
    paths = injectivity_files()
    if jobs > 1:
        from ccproof.scale.processes import process_pool

        with process_pool(jobs) as ex:  # Ctrl-C: one line, the workers stopped
            rows = list(ex.map(_row, paths))
    else:
        from tqdm import tqdm

        rows = [_row(p) for p in tqdm(paths, desc="verify", unit="certificate", leave=False, disable=not progress)]
    # single valences by k, then the intervals, then the files without a readable valence
    return sorted(rows, key=lambda r: (r["k"] is None, () if r["k"] is None else (r["k"].interval, r["k"].k)))


def markdown(rows):
    head = ("| k | N | lam | min det J_Phi (layer 0, w.r.t. (u,v)) | min det J_G cells (w.r.t. y) | "
            "min det J_G / h^2 corner | verify s |\n|---|---|---|---|---|---|---|\n")
    body = "".join(
        f"| {_kname(r['k'])} | {r['N']} | {r['lam']} | {r['detPhi']:.4g} | {r['detG_cells']:.4g} | "
        f"{r['detG_corner']:.4g} | {r['verify_s']} |\n" if r["ok"] else
        f"| {_kname(r['k'])} | FAILED: {r['path']} | | | | | {r['verify_s']} |\n"
        for r in rows)
    return head + body


def _kname(k):
    """``5`` or ``>= 40`` (the Markdown table's spelling of a :class:`~ccproof.valence.Valence`)."""
    return "?" if k is None else f">= {k.k}" if k.interval else str(k)


def tagged_table():
    """Markdown table of the tagged certificates, each re-verified in this run (the reason column is the
    verifier's message on the spectrum: lam1, lam2 and, for a witness, gamma), then the coverage of each
    tagged family as the verifier decides it from these verdicts (with the undecided configurations and
    their reasons)."""
    from ccproof.certify.verify import certificate_files, coverage, verify_file
    from ccproof.certify.verify.registry import TAGGED
    from ccproof.cli.verify import summary
    from ccproof.tables.format import certificates_dir

    head = "| configuration | statement | verdict | spectrum (re-derived) | verify s |\n|---|---|---|---|---|\n"
    body, results = "", []
    for path in certificate_files(certificates_dir()):
        if path.parent.name not in TAGGED:
            continue
        res = verify_file(path, log=lambda line: None)
        results.append(res)
        row = summary(res)
        spec = next((p["message"] for p in row["parts"] if p["name"].startswith(("G ", "spectral"))), "")
        spec = spec.removeprefix(f"{row['configuration']}: ").removeprefix("1 simple; ").split(";")[0]
        body += (f"| {row['configuration']} | {row['statement']} | {row['verdict']} | {spec} | "
                 f"{row['seconds']:.1f} |\n")
    tagged = [line for line in coverage(results)[1] if line.split(":")[0] in TAGGED]
    return head + body + "\n" + "\n".join(f"* {line}" for line in tagged) + "\n"


def run(args):
    from pathlib import Path

    from ccproof.cli._output import PLOT_SUFFIXES, atomic, check_file, write_text
    from ccproof.errors import CCProofError
    from ccproof.scale.processes import check_jobs

    # as every command: >= 1, at most the cores and the certificates (one line on stderr when it caps)
    jobs = check_jobs(args.jobs, tasks=None if args.tagged else len(injectivity_files()))
    if args.tagged and (args.write or args.plot):
        raise CCProofError(f"{'--write' if args.write else '--plot'} applies to the table of the valences, not to "
                           "--tagged")
    out = Path("docs/certified_valences.md")
    if args.write:  # every output checked before the certificates are re-verified
        check_file(out, (".md",), "--write")
    if args.plot:
        check_file(args.plot, PLOT_SUFFIXES, "--plot")
    from ccproof.cli._progress import progress_enabled

    if args.tagged:
        print(tagged_table())
        return 0
    rows = collect(jobs, progress_enabled(args))
    md = markdown(rows)
    print(md)
    if args.write:
        write_text(out, "# Certified valences\n\nGenerated by `ccproof report --write`. Every number is the smallest "
                   "lower bound that `ccproof verify` re-checked in that run on the certificates in "
                   "certificates/injectivity/; "
                   "the cells' det J_G is converted to the face parameter y (x 4^N), det J_Phi to (u,v) (x 4); "
                   "see docs/appendix_a.md.\n\n" + md)
        print(f"wrote {out}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        rows = [r for r in rows if r["ok"]]
        single = [r for r in rows if not r["k"].interval]
        ks = [r["k"].k for r in single]
        fig, ax = plt.subplots(figsize=(7, 4))
        keys = (("detPhi", "o-", "C0", "min det J_Phi (layer 0, w.r.t. (u,v))"),
                ("detG_corner", "s-", "C1", "min det J_G / h^2 (corner)"),
                ("detG_cells", "^-", "C2", "min det J_G (cells, w.r.t. y)"))
        for key, style, color, label in keys:
            ax.plot(ks, [r[key] for r in single], style, color=color, label=label)
        for r in rows:
            if r["k"].interval:  # the band k >= k0: one bound for all of them
                k0, k1 = r["k"].k, r["k"].k + 25
                ax.axvspan(k0, k1, color="0.9", zorder=0)
                for key, _, color, _ in keys:
                    ax.hlines(r[key], k0, k1, colors=color, linestyles="--")
                ax.text(k0 + 1, 1.1, f"all k >= {k0}\n(one certificate)", fontsize=8)
        ax.set_xlabel("valence k")
        ax.set_ylabel("certified lower bound")
        ax.set_title("Certified injectivity margins (bmz04 Appendix A, corrected)")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        with atomic(args.plot) as tmp:
            fig.savefig(tmp, dpi=120)
        print(f"wrote {args.plot}")
    return 0
