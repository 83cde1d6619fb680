"""Prove that the characteristic-map reparameterization of bmz04 is injective for a valence.

  ccproof certify 5             prove valence 5, print the certified margins, write
                                certificates/injectivity/k005.json, then re-check it with the verifier
  ccproof certify 7 --out DIR   write the certificate to DIR/k007.json instead
  ccproof certify 3-39          all valences 3..39 on a local Dask cluster (one worker per core)
  ccproof certify 3-39 --serial  the same in this process; --scheduler local:2 or tcp://host:8786
                                 for 2 local workers or a running Dask scheduler (docs/scale-out.md)
  ccproof certify 3-39 --c1      C1 certificates (Reif's criterion: spectrum, regular and injective
  ccproof certify '>=40' --c1    characteristic map) for valences 3..39 and for every k >= 40 at once
  ccproof certify crease:1-30 --c1   tagged configurations (dart:K, crease:N, corner:N; docs/tagged_c1.md):
                                 a "not C1" certificate with a witness where one is found, else a "C1"
                                 certificate (characteristic map regular and injective), written to
                                 certificates/c1/FAMILY/; the others reported as undecided with the reason
  ccproof certify 'crease:>=101' --c1   every N >= 101 at once (crease or corner, "not C1": one witness shape,
                                 the normal's limit checked on a disc in theta = pi/N), written to
                                 certificates/c1/FAMILY/n_ge_101.json
  ccproof certify 'dart:>=101' --c1   every dart K >= 101 at once ("C1": spectrum through a secular equation,
                                 the eigenvectors and the characteristic map as analytic families in h = 1/K;
                                 about 30 s, then 20 s for the verifier), certificates/c1/dart/k_ge_101.json
  ccproof certify '>=40'         the Appendix-A statement for every k >= 40 in one certificate: lam is a
                                 variable (Taylor models in zeta, lam = mid + zeta * half-width), see
                                 docs/appendix_a.md section 6

The proof follows bmz04 Appendix A as corrected in docs/appendix_a.md: N(k) dyadic subdivisions (R8),
every polynomial piece of the weight met by each subpatch, and the corner subpatch for all layers
at once in the scale variables (rho, kappa) (R9). Floats never decide: every bound is an arb ball.

Where new certificates go by default: the repository's certificates/injectivity/ (certificates/c1/
with --c1) when ccproof runs from a checkout; for an installed package, which only reads its
published certificates, $XDG_DATA_HOME/ccproof/certificates/injectivity/ (XDG_DATA_HOME defaults to
~/.local/share), never inside site-packages. The verifier reads no table: it derives the statement
(c, lam, eigenvector, nets) from k and the Catmull-Clark rules and checks only the boxes of the file
(docs/trusted_base.md).
"""

from __future__ import annotations

from ccproof.errors import CCProofError


def add_arguments(p):
    p.add_argument("valences", help="a valence K, a range A-B (e.g. 3-39), or '>=K0' (every k >= K0 at once)")
    p.add_argument("--c1", action="store_true",
                   help="certify Reif's C1 criterion (regular, injective characteristic map) instead")
    p.add_argument("--prec", type=int, default=128, help="arb precision in bits (default 128)")
    p.add_argument("--jobs", type=int, default=None, help="same as --scheduler local:JOBS (kept for old scripts; >= 1, "
                   "at most the cores of this machine and the number of tasks)")
    from ccproof.scale.engine import add_scheduler_arguments

    add_scheduler_arguments(p)
    p.add_argument("--out", default=None,
                   help="folder for the new certificates (default: see above; certificates/injectivity in a checkout)")
    p.add_argument("--no-verify", action="store_true", help="do not re-check the written certificate")
    p.add_argument("--truncation-degree", type=int, default=2,
                   help="for '>=K0': zeta degree kept in the cell Taylor models (default 2)")
    p.add_argument("--max-pieces", type=int, default=16,
                   help="for '>=K0': most lam pieces of the bisection (default 16); the pieces of each bisection "
                        "wave run as tasks on --scheduler")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(p)


def parse_valences(text):
    """The valences of the command line: ``K``, ``A-B`` (every K in A..B) or ``'>=K0'`` (one interval),
    as a list of :class:`~ccproof.valence.Valence`.

    >>> parse_valences("3-5"), parse_valences(">=40")
    ([Valence('3'), Valence('4'), Valence('5')], [Valence('>=40')])
    """
    from ccproof.errors import CCProofError
    from ccproof.valence import Valence

    text = str(text).strip()
    a, dash, b = text.partition("-")
    if dash and a and ">" not in text:
        lo, hi = Valence.parse(a), Valence.parse(b)
        if hi.k < lo.k:
            raise CCProofError(f"empty valence range {text!r}")
        _verifiable(hi)
        return [Valence(k) for k in range(lo.k, hi.k + 1)]
    return [_verifiable(Valence.parse(text))]


def _verifiable(v):
    """``v`` if the verifier accepts its valence field, else a :class:`CCProofError` quoting the verifier's
    bound (asked of the verifier's own reader, so that the two never disagree), before any proof runs.

    >>> from ccproof.valence import Valence
    >>> _verifiable(Valence(10**9))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: valence 1000000000: ... (valence 1000000000 outside 3..10^6)
    """
    from ccproof.certify.verify.errors import CertificateError
    from ccproof.certify.verify.record import read_valence
    from ccproof.errors import CCProofError

    try:
        read_valence({"valence": {"min": v.k} if v.interval else v.k})
    except CertificateError as exc:
        raise CCProofError(f"valence {v}: ccproof verify would reject its certificate ({exc})") from None
    return v


def _one(args):
    """One task of a sweep: prove a valence; returns the certificate (the caller writes it, so that a
    remote worker needs no shared file system) and its timing."""
    k, prec, out, progress = args
    import time

    from ccproof.certify.prover import prove_valence

    t0 = time.perf_counter()
    cert = prove_valence(k, prec=prec, progress=progress)
    return cert, round(time.perf_counter() - t0, 2)


def _run_c1(ks, args):
    from ccproof.certify.prover import c1_certificate_path, prove_c1, write_certificate

    ok_all = True
    for k in ks:
        cert = prove_c1(k, prec=args.prec)
        path = write_certificate(cert, c1_certificate_path(k, args.out))
        parts = cert["pieces"][0]["parts"] if "pieces" in cert else cert["parts"]
        mins = {n: min(b["bound"] for b in v) for sec in parts.values() for n, v in sec.items()}
        print(f"valence {k}: C1 certificate written to {path}; root bounds {mins}")
        ok_all &= _recheck(path, args)
    return 0 if ok_all else 1


def _run_interval(k, args):
    import time

    from ccproof.certify.prover import certificate_path, claimed_margins, prove_interval, write_certificate

    t0 = time.perf_counter()
    from ccproof.scale.engine import scheduler_from_args

    sched = scheduler_from_args(args)
    from ccproof.cli._progress import progress_enabled

    cert = prove_interval(k, prec=args.prec, truncation_degree=args.truncation_degree, max_pieces=args.max_pieces,
                          scheduler=None if sched.kind == "serial" else sched, progress=progress_enabled(args))
    seconds = time.perf_counter() - t0
    path = write_certificate(cert, certificate_path(k, args.out))
    summary, boxes = claimed_margins(cert)
    print(f"valences {k}: N = {cert['N']}, {len(cert['pieces'])} lam piece(s) "
          f"{[p['lam'] for p in cert['pieces']]}, {boxes} boxes, {seconds:.1f} s")
    _print_summary(summary)
    print(f"  certificate written to {path}")
    return 0 if _recheck(path, args) else 1


def _print_summary(summary):
    print("  bounds claimed by the prover (re-checked below by the verifier):")
    print(f"  min det J_Phi bound (local)        {float_str(summary['min_bound_det_J_phi_local'])}")
    print(f"  min det J_G bound, cells (local)   {float_str(summary['min_bound_det_J_G_cells_local'])}")
    print(f"  min det J_G / h^2 bound, corner    {float_str(summary['min_bound_det_J_G_corner_over_h2'])}")


def _run_tagged(args):
    import time

    from ccproof.certify.prover import prove_configuration
    from ccproof.certify.tagged import configurations, write_tagged

    ok_all = True
    for name in configurations(args.valences):
        t0 = time.perf_counter()
        cert, why = prove_configuration(name, prec=args.prec)  # the registry's routes: "not C1", then "C1"
        seconds = time.perf_counter() - t0
        if cert is None:
            print(f"{name}: {why} ({seconds:.1f} s); no certificate written")
            continue
        path = write_tagged(cert, args.out)
        print(f"{name}: {why}; certificate written to {path} ({seconds:.1f} s)")
        ok_all &= _recheck(path, args)
    return 0 if ok_all else 1


def run(args):
    tagged = ":" in str(args.valences)
    if tagged and not args.c1:
        raise CCProofError(f"{args.valences}: tagged configurations (FAMILY:N) are certified with --c1")
    if args.out is None:
        from ccproof.tables.format import output_dir

        args.out = str(output_dir() / ("c1" if args.c1 else "injectivity"))
    from ccproof.cli._output import check_folder

    args.out = str(check_folder(args.out))  # before any proof; absolute, whatever folder a worker runs in
    if tagged:
        return _run_tagged(args)
    ks = parse_valences(args.valences)
    _check_options(args, ks)
    if args.c1:
        return _run_c1(ks, args)
    if ks[0].interval:
        return _run_interval(ks[0], args)
    from ccproof.certify.prover import certificate_path, claimed_margins, write_certificate
    from ccproof.cli._progress import progress_enabled
    from ccproof.scale.engine import open_scheduler, run_tasks, scheduler_from_args

    progress = progress_enabled(args)
    work = [(k.k, args.prec, args.out, len(ks) == 1 and progress) for k in ks]
    names = [f"valence {k}" for k in ks]
    with open_scheduler(scheduler_from_args(args), len(ks)) as sched:
        sweep = run_tasks(_one, work, sched, desc="certify", unit="valence", priority=[w[0] for w in work],
                          names=names, raise_errors=False, progress=progress)
        for line in sweep.report(names):
            print(line)
        ok_all = not sweep.errors
        written = []
        for k, res in zip(ks, sweep.results):
            if res is None:
                continue
            cert, seconds = res
            path = write_certificate(cert, certificate_path(k, args.out))
            summary, boxes = claimed_margins(cert)
            print(f"valence {k}: N = {cert['N']}, {boxes} boxes, {seconds} s")
            _print_summary(summary)
            print(f"  certificate written to {path}")
            written.append(path)
        if not args.no_verify and written:
            from ccproof.cli.verify import verify_task

            check = run_tasks(verify_task, [(str(p), True) for p in written], sched, desc="verify", unit="file",
                              names=[str(p) for p in written], raise_errors=False, progress=progress)
            for line in check.report([str(p) for p in written]):
                print(line)
            for i, (p, res) in enumerate(zip(written, check.results)):
                verdict = bool(res and res[0])
                seconds = res[0].seconds if res else float("nan")
                why = "" if verdict else f": {_failure_reason(res, check.errors.get(i))}"
                print(f"  independent verifier on {p}: {'VERIFIED' if verdict else 'FAILED'} ({seconds:.1f} s){why}")
                ok_all &= verdict
    return 0 if ok_all else 1


def _check_options(args, ks):
    """Refuse, before any proof, options that would give a certificate ``ccproof verify`` rejects: the
    precision is asked of the verifier's own reader, the truncation degree against the prover's Taylor
    degree (the verifier requires 1 <= truncation_degree <= taylor_degree)."""
    import inspect

    from ccproof.certify.prover import prove_interval
    from ccproof.certify.verify.errors import CertificateError
    from ccproof.certify.verify.injectivity import read_n_prec
    from ccproof.errors import CCProofError

    try:
        read_n_prec({"N": 1, "prec": args.prec})
    except CertificateError:
        raise CCProofError(f"--prec {args.prec}: ccproof verify accepts certificates of 64..1024 bits only") from None
    taylor = inspect.signature(prove_interval).parameters["taylor_degree"].default
    if ks[0].interval and not args.c1 and not 1 <= args.truncation_degree <= taylor:
        raise CCProofError(f"--truncation-degree {args.truncation_degree}: must lie in 1..{taylor} (the Taylor "
                           "degree of the lam variable), or ccproof verify rejects the certificate")


def _failure_reason(res, exc=None):
    """Why a verification failed: the task's exception, the verifier's error or its failed parts.

    >>> _failure_reason(None, OSError("no such file"))
    'the task failed: OSError: no such file'
    """
    if res is None:
        return f"the task failed: {type(exc).__name__}: {exc}" if exc is not None else "the task failed"
    r = res[0]
    if r.error:
        return r.error
    return "; ".join(f"{p.name}: {p.message}" if p.message else p.name for p in r.failures()) or "failed"


def _recheck(path, args):
    """Re-check a written certificate with the independent verifier (unless --no-verify); True if it passed."""
    if args.no_verify:
        return True
    import time

    from ccproof.certify.verify import verify_file

    t0 = time.perf_counter()
    res = verify_file(path, log=lambda s: None)
    ok = bool(res)
    why = "" if ok else f": {_failure_reason((res,))}"
    print(f"  independent verifier: {'VERIFIED' if ok else 'FAILED'} ({time.perf_counter() - t0:.1f} s){why}")
    return ok


def float_str(q):
    from fractions import Fraction

    return f"{float(Fraction(q)):.6g}  (= {q})"
