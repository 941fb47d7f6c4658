#!/usr/bin/python3
"""Compares a hemosolve run of a Boileau et al. (2015) benchmark case with the reference.

usage: compare_boileau.py CASE RUN_DIR [--plot OUT.png] [--max-eps-p 0.002] [--max-eps-q 0.005]
       compare_boileau.py CASE --print-probes      (the hemosolve --probe flags, one per line)
       compare_boileau.py CASE --check-reference   (exit 0 if the reference is there, 77 if not)

CASE is cca or ibif (uta comes with its inflow only: no reference, skipped). RUN_DIR holds
hemosolve's probes.csv: a header row whose first column is the time `t [s]`, then for each
probe `p vessel ID x X [Pa]`, `Q vessel ID x X [m^3/s]`, `A ...`, `u ...`; rows are time
samples covering at least the last full cycle, t counted from the start of the run.

The reference is the benchmark's 1D finite-volume solution (FV_*.dat: t [s], P [kPa],
Q [ml/s], ...), read from --reference-dir, else $HEMOTREE_VALIDATION_DIR (the boileau2015
folder itself, or a folder holding boileau2015/), else ../shared/validation/boileau2015 from
the project root. It is never copied into the project.

Over the last full cycle of each series (the last period T before its final sample; T from
the case file's inlet waveform), both are aligned on the cycle phase t mod T and ours is
interpolated, periodically, onto the reference samples. The measures (the data README's):
  eps_P = mean |P - P_ref| / P_ref,   eps_Q = mean |Q - Q_ref| / max |Q_ref|,
  and the relative errors of max P, min P (against the reference's) and max Q (against
  max |Q_ref|), the extremes taken over each series' own samples.
Exit status: 0 all locations within the thresholds, 1 some location beyond them, 2 unusable
input (no probes.csv, a probe missing, less than one cycle), 77 reference not found
(CTest's SKIP_RETURN_CODE). The cases, the reference lookup and the measures are those of
python/hemotree_boileau.py (scripts/validation-report uses the same); probes.csv is read by
python/hemotree_io.py.
"""
import argparse
import math
import sys
from pathlib import Path

PROJECT = Path(__file__).resolve().parent.parent.parent
sys.dont_write_bytecode = True  # no __pycache__ left in python/
sys.path.insert(0, str(PROJECT / "python"))
# The cases, the reference lookup and the measures: shared with scripts/validation-report.
from hemotree_boileau import (CASES, KPA, ML, InputProblem, compare_location,  # noqa: E402
                              probe_column, probe_flag, read_probes, read_table, reference_dir)
import hemotree_io  # noqa: E402

SKIP = 77


def plot(out, case, results, ref_dir, period):
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(results), 2, figsize=(12, 3.4 * len(results)), squeeze=False)
    for row, (label, vessel, x, b3d_name, m, c) in enumerate(results):
        b3d = None
        if (ref_dir / case / b3d_name).is_file():
            b3d = read_table(ref_dir / case / b3d_name)
        for col, (key, unit, scale) in enumerate([("p", "P [kPa]", KPA), ("q", "Q [ml/s]", ML)]):
            ax = axes[row][col]
            o = np.argsort(c["phase_ref"])
            ax.plot(c["phase_ref"][o], c[f"{key}_ref"][o] / scale, "k-", lw=1.6,
                    label="1D FV reference (Boileau et al. 2015)")
            if b3d is not None:
                ax.plot(np.mod(b3d[:, 0], period), b3d[:, 1 + col], "-", color="0.6", lw=1,
                        label="3D (Boileau et al. 2015)")
            o = np.argsort(c["phase_ours"])
            ax.plot(c["phase_ours"][o], c[f"{key}_ours"][o] / scale, "r--", lw=1.2,
                    label="hemosolve")
            ax.set_xlabel("t mod T [s]")
            ax.set_ylabel(unit)
            eps = m["eps_P"] if key == "p" else m["eps_Q"]
            name = "eps_P" if key == "p" else "eps_Q"
            ax.set_title(f"{case}: {label} (vessel {vessel}, x {x:g}), {name} {100 * eps:.3f} %",
                         fontsize=10)
            ax.grid(alpha=0.3)
            if row == 0:
                ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv):
    parser = argparse.ArgumentParser(
        description="Compares hemosolve's probes with the Boileau et al. (2015) 1D reference.")
    parser.add_argument("case", choices=sorted(CASES))
    parser.add_argument("run_dir", nargs="?", help="hemosolve's output folder (probes.csv)")
    parser.add_argument("--plot", metavar="OUT.png", help="draw ours over the reference")
    parser.add_argument("--max-eps-p", type=float, default=0.002, help="default 0.002 (0.2 %%)")
    parser.add_argument("--max-eps-q", type=float, default=0.005, help="default 0.005 (0.5 %%)")
    parser.add_argument("--case-file", help="default examples/boileau2015/CASE.json")
    parser.add_argument("--reference-dir", help="the boileau2015 folder of the reference data")
    parser.add_argument("--print-probes", action="store_true",
                        help="print the hemosolve flags for the probes compared, one per line")
    parser.add_argument("--check-reference", action="store_true",
                        help="exit 0 if the reference is found, 77 if not")
    args = parser.parse_args(argv)
    locations = CASES[args.case]

    if args.print_probes:
        for _, vessel, x, _, _ in locations:
            print("--probe")
            print(probe_flag(vessel, x))
        return 0

    if not locations:
        print(f"skipped: {args.case} has no reference waveforms (the benchmark gives its inflow only)")
        return SKIP
    ref_dir, origin = reference_dir(args.reference_dir)
    missing = [name for _, _, _, name, _ in locations if not (ref_dir / args.case / name).is_file()]
    if missing:
        print(f"skipped: reference {ref_dir / args.case}/{missing[0]} not found ({origin}; set "
              f"HEMOTREE_VALIDATION_DIR to the boileau2015 folder)")
        return SKIP
    if args.check_reference:
        print(f"reference: {ref_dir / args.case}")
        return 0
    if not args.run_dir:
        parser.error("RUN_DIR is required")

    try:
        case_file = Path(args.case_file or PROJECT / "examples" / "boileau2015" / f"{args.case}.json")
        try:
            period = float(hemotree_io.read_network(case_file).inlet["waveform"]["period"])
        except (OSError, ValueError, KeyError, TypeError, hemotree_io.MissingDependency) as e:
            raise InputProblem(f"{case_file}: cannot read inlet.waveform.period ({e})")
        if not (period > 0 and math.isfinite(period)):
            raise InputProblem(f"{case_file}: the period must be positive")
        path, t, probes = read_probes(args.run_dir)
        results = []
        for label, vessel, x, fv, b3d in locations:
            where = f"{path} (vessel {vessel}, x {x:g})"
            p = probe_column(probes, "p", vessel, x, path)
            q = probe_column(probes, "Q", vessel, x, path)
            ref = read_table(ref_dir / args.case / fv)
            m, curves = compare_location(t, p, q, ref, period, where)
            results.append((label, vessel, x, b3d, m, curves))
    except InputProblem as e:
        print(f"compare_boileau: {e}", file=sys.stderr)
        return 2

    failed = []
    print(f"{args.case}: hemosolve ({args.run_dir}) against the 1D FV reference "
          f"({ref_dir / args.case}), last cycle, T = {period:g} s")
    for label, vessel, x, _, m, _ in results:
        ok = m["eps_P"] <= args.max_eps_p and m["eps_Q"] <= args.max_eps_q
        if not ok:
            failed.append(label)
        print(f"  {label + ' (vessel %d, x %g)' % (vessel, x):38s} "
              f"eps_P {100 * m['eps_P']:7.4f} %  eps_Q {100 * m['eps_Q']:7.4f} %  "
              f"max P {100 * m['max_P']:+8.4f} %  min P {100 * m['min_P']:+8.4f} %  "
              f"max Q {100 * m['max_Q']:+8.4f} %  {'ok' if ok else 'FAIL'}")
    if args.plot:
        plot(args.plot, args.case, results, ref_dir, period)
        print(f"  plot: {args.plot}")
    limits = f"eps_P <= {100 * args.max_eps_p:g} %, eps_Q <= {100 * args.max_eps_q:g} %"
    if failed:
        print(f"FAIL: {args.case}: {', '.join(failed)} beyond {limits}")
        return 1
    print(f"PASS: {args.case}: {len(results)} location(s) within {limits}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
