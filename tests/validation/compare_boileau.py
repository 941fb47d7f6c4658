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
(CTest's SKIP_RETURN_CODE).
"""
import argparse
import csv
import json
import math
import os
import re
import sys
from pathlib import Path

PROJECT = Path(__file__).resolve().parent.parent.parent
SKIP = 77

# Per case, the compared locations: (label, vessel id, x along the vessel [0, 1], FV file,
# matching 3D file). The vessel ids are those make-cases gives (examples/boileau2015):
# cca: 1 the carotid; ibif: 1 the aorta, 2 and 3 the iliacs.
CASES = {
    "cca": [("carotid midpoint", 1, 0.5, "FV_carotid.dat", "B3D_commoncarotid.txt")],
    "ibif": [("aorta midpoint", 1, 0.5, "FV_aorta-bif.dat", "B3D_AortaMid.txt"),
             ("aorta at the junction", 1, 1.0, "FV_aorta_bif-bif.dat", "B3D_Junction.txt"),
             ("iliac midpoint", 2, 0.5, "FV_iliac-bif.dat", "B3D_IliacMid.txt")],
    "uta": [],
}
KPA, ML = 1e3, 1e-6   # reference units to SI: kPa -> Pa, ml/s -> m^3/s


class InputProblem(Exception):
    pass


def probe_flag(vessel, x):
    return f"{vessel}:{x:g}"


def reference_dir(arg):
    """The boileau2015 folder and where its location came from."""
    if arg:
        return Path(arg), "--reference-dir"
    env = os.environ.get("HEMOTREE_VALIDATION_DIR")
    if env:
        path = Path(env)
        if (path / "boileau2015").is_dir():
            path = path / "boileau2015"
        return path, "HEMOTREE_VALIDATION_DIR"
    return PROJECT.parent / "shared" / "validation" / "boileau2015", "default"


def read_table(path):
    import numpy as np
    rows = [line.split() for line in open(path) if line.strip() and not line.startswith("#")]
    return np.array([[float(v) for v in r] for r in rows])


def read_probes(run_dir):
    """(time array, {(kind, vessel, x): column array}) from RUN_DIR/probes.csv."""
    import numpy as np
    path = Path(run_dir) / "probes.csv"
    if not path.is_file():
        raise InputProblem(f"{path} not found")
    with open(path, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    reader = csv.reader(lines)
    try:
        header = [h.strip() for h in next(reader)]
    except StopIteration:
        raise InputProblem(f"{path}: empty")
    if not header or not header[0].startswith("t"):
        raise InputProblem(f"{path}: the first column must be the time `t [s]`, not {header[:1]}")
    columns = {}
    pattern = re.compile(r"^(p|Q|A|u)\s+vessel\s+(-?\d+)\s+x\s+([-+0-9.eE]+)\s*(\[.*\])?$")
    for k, name in enumerate(header[1:], start=1):
        m = pattern.match(name)
        if m:
            columns[(m.group(1), int(m.group(2)), float(m.group(3)))] = k
    try:
        data = np.array([[float(v) for v in row] for row in reader if row])
    except ValueError as e:
        raise InputProblem(f"{path}: {e}")
    if data.ndim != 2 or data.shape[0] < 3 or data.shape[1] != len(header):
        raise InputProblem(f"{path}: expected rows of {len(header)} numbers under the header")
    return path, data[:, 0], {key: data[:, k] for key, k in columns.items()}


def probe_column(probes, kind, vessel, x, path):
    for (k, v, px), column in probes.items():
        if k == kind and v == vessel and abs(px - x) < 1e-6:
            return column
    have = sorted({probe_flag(v, px) for (_, v, px) in probes})
    raise InputProblem(f"{path}: no column `{kind} vessel {vessel} x {x:g}` "
                       f"(probes there: {', '.join(have) or 'none'}; run hemosolve with "
                       f"--probe {probe_flag(vessel, x)})")


def last_cycle(t, period, what):
    """Indices of the samples in (t_end - T, t_end], checking they cover a whole cycle."""
    import numpy as np
    steps = np.diff(t)
    if np.any(steps <= 0):
        raise InputProblem(f"{what}: times must increase")
    dt = float(np.median(steps))
    start = t[-1] - period
    if t[0] > start + 1.5 * dt:
        raise InputProblem(f"{what}: {t[-1] - t[0]:.4g} s of samples, less than a full cycle "
                           f"of {period:g} s")
    return np.nonzero(t > start + 0.5 * dt)[0]


def periodic_interp(phase_at, t, values, period):
    import numpy as np
    return np.interp(phase_at, np.mod(t, period), values, period=period)


def compare_location(t_ours, p_ours, q_ours, ref, period, where):
    import numpy as np
    i = last_cycle(t_ours, period, where)
    j = last_cycle(ref[:, 0], period, "reference")
    t_ref = ref[j, 0]
    p_ref, q_ref = ref[j, 1] * KPA, ref[j, 2] * ML
    phase = np.mod(t_ref, period)
    p = periodic_interp(phase, t_ours[i], p_ours[i], period)
    q = periodic_interp(phase, t_ours[i], q_ours[i], period)
    q_scale = float(np.max(np.abs(q_ref)))
    m = {
        "eps_P": float(np.mean(np.abs(p - p_ref) / p_ref)),
        "eps_Q": float(np.mean(np.abs(q - q_ref)) / q_scale),
        "max_P": float((p_ours[i].max() - p_ref.max()) / p_ref.max()),
        "min_P": float((p_ours[i].min() - p_ref.min()) / p_ref.min()),
        "max_Q": float((q_ours[i].max() - q_ref.max()) / q_scale),
    }
    curves = {"phase_ref": phase, "p_ref": p_ref, "q_ref": q_ref,
              "phase_ours": np.mod(t_ours[i], period), "p_ours": p_ours[i], "q_ours": q_ours[i]}
    return m, curves


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
            period = float(json.load(open(case_file))["inlet"]["waveform"]["period"])
        except (OSError, ValueError, KeyError, TypeError) as e:
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
