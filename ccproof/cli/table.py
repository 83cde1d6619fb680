"""Print or regenerate the certified characteristic-map tables.

  ccproof table K          summary of the table of valence K (lam, N, det J_Phi bounds, hash)
  ccproof table '>=40'     summary of the table for every valence k >= 40
  ccproof table --all      regenerate certificates/tables/ for k = 3..100 and k >= 40 (progress bar)

Tables hold the exact nets of the characteristic-map pieces P1, P2, P3 (bmz04 section 4.3) in
c = cos(2 pi/k) and lam, their arb enclosures, float64 copies and derived quantities certified with
Bernstein bounds; see docs/tables.md.
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("valence", nargs="?", help="valence K >= 3, or '>=K0' for the interval table")
    p.add_argument("--all", action="store_true", help="regenerate every table (k = 3..100 and k >= 40)")
    p.add_argument("--kmax", type=int, default=100, help="largest valence with --all (default 100)")
    p.add_argument("--jobs", type=int, default=2, help="worker processes with --all (default 2; >= 1, at most "
                   "the cores of this machine and the number of tables)")
    p.add_argument("--dir", default=None, help="tables folder for --all (default: certificates/tables of the "
                   "checkout, or the user folder of an installed package, never site-packages)")
    p.add_argument("--json", action="store_true", help="print the raw JSON instead of a summary")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(p)


def _summary(obj):
    from ccproof.tables.format import arb_from_json

    d = obj["derived"]
    prec = obj["prec"]

    def ball(x):
        return arb_from_json(x, prec).str(12, radius=False)

    from ccproof.valence import Valence

    v = Valence.parse(obj["valence"])
    name = f"k >= {v.k}" if v.interval else f"k = {v.k}"
    lines = [
        f"characteristic map table, {name}  ({obj['schema']}, {prec} bits)",
        f"  c = cos(2 pi/k)        {ball(obj['c'])}",
        f"  lam (subdominant)      {ball(obj['lam'])}",
        f"  spectral ordering      {'certified' if obj['spectral']['ok'] else 'NOT certified'}",
        f"  N (R8)                 {d['N']}{'  (minimal)' if d['N_is_minimal'] else ''}",
        f"  min det J_Phi layer 0  in [{ball(d['det_jacobian_phi']['min_lower'])}, "
        f"{ball(d['det_jacobian_phi']['min_upper'])}]",
        f"  max Phi_x on the face  in [{ball(d['max_coordinate']['lower'])}, {ball(d['max_coordinate']['upper'])}]",
        f"  [0,1/2]^2 in image     {d['square_inside_image']}",
        f"  max |Phi| outer bdry   <= {ball(d['max_norm_outer_boundary']['upper'])}",
        f"  hash                   {obj['hash']}",
    ]
    return "\n".join(lines)


def _build_one(args):
    k, directory = args
    from ccproof.tables.build import write_table

    return str(write_table(k, directory))


#: the temporary name of a table being written by process PID (ccproof.tables.build.write_table)
_TEMPORARY_TABLE = r"^\.tmp-(\d+)-k(?:_ge_)?[0-9]+\.json$"


def _remove_dead_temporaries(folder):
    """Remove the temporary tables in ``folder`` whose writer is gone (a worker stopped in the middle of a
    write, or killed with its parent); returns how many."""
    import os
    import re

    from ccproof.scale.processes import pid_alive

    try:
        names = os.listdir(folder)
    except OSError:  # not there yet: the first table creates it
        return 0
    n = 0
    for name in names:
        m = re.match(_TEMPORARY_TABLE, name)
        if m and not pid_alive(int(m.group(1))):
            try:
                os.unlink(os.path.join(folder, name))
                n += 1
            except OSError:
                pass
    return n


def run(args):
    import json

    from ccproof.errors import CCProofError, TableNotFoundError
    from ccproof.tables.format import describe_available, read_table_json, table_path
    from ccproof.valence import Valence

    if args.all:
        if args.kmax < 3:
            raise CCProofError(f"--kmax must be >= 3 (the smallest valence), got {args.kmax}")
        from tqdm import tqdm

        from ccproof.cli._output import check_folder
        from ccproof.cli._progress import progress_enabled
        from ccproof.scale.processes import check_jobs
        from ccproof.tables.build import DEFAULT_INTERVAL_K0
        from ccproof.tables.format import output_dir

        ks = [Valence(k) for k in range(3, args.kmax + 1)] + [Valence(DEFAULT_INTERVAL_K0, interval=True)]
        args.dir = str(check_folder(args.dir or str(output_dir() / "tables"), "--dir"))  # before any work
        work = [(k, args.dir) for k in ks]
        jobs = check_jobs(args.jobs, tasks=len(work))  # as every command: >= 1, at most the cores and the tasks
        from ccproof.scale.processes import process_pool

        _remove_dead_temporaries(args.dir)  # of a run killed before
        try:
            with process_pool(jobs) as ex:  # Ctrl-C: one line, the workers stopped
                for _ in tqdm(ex.map(_build_one, work), total=len(work), desc="tables", unit="table",
                              disable=not progress_enabled(args)):
                    pass
        finally:  # a worker stopped while it wrote leaves its temporary table: nothing half-written stays
            _remove_dead_temporaries(args.dir)
        print(f"wrote {len(work)} tables; {describe_available(args.dir)}")
        return 0
    if args.valence is None:
        raise CCProofError("give a valence K (or '>=K0'), or --all")
    v = Valence.parse(args.valence)
    path = table_path(v, args.dir)
    try:
        obj = read_table_json(path)
    except FileNotFoundError:
        raise TableNotFoundError(f"no table for {v}; {describe_available(args.dir)}") from None
    print(json.dumps(obj, indent=1) if args.json else _summary(obj))
    return 0
