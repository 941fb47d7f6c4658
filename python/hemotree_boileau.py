"""The Boileau et al. (2015) benchmark (examples/boileau2015): its compared locations, its
reference data and the measures of a hemosolve run against it, shared by
tests/validation/compare_boileau.py (the validation tests) and scripts/validation-report,
so that both measure alike.

The reference is the benchmark's 1D finite-volume solution (FV_*.dat: t [s], P [kPa],
Q [ml/s], ...), read from a given folder, else $HEMOTREE_VALIDATION_DIR (the boileau2015
folder itself, or a folder holding boileau2015/), else ../shared/validation/boileau2015 from
the project root. It is never copied into the project.

Over the last full cycle of each series (the last period T before its final sample), both are
aligned on the cycle phase t mod T and ours is interpolated, periodically, onto the reference
samples. The measures (the data README's):
  eps_P = mean |P - P_ref| / P_ref,   eps_Q = mean |Q - Q_ref| / max |Q_ref|,
  and the relative errors of max P, min P (against the reference's) and max Q (against
  max |Q_ref|), the extremes taken over each series' own samples.
"""
import os
from pathlib import Path

import hemotree_io

PROJECT = Path(__file__).resolve().parent.parent

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
    """Unusable input: a run without the probes compared, less than a cycle of samples."""


def probe_flag(vessel, x):
    """hemosolve's --probe value for the probe at X along vessel VESSEL."""
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
    """A reference file (columns of numbers separated by blanks, # comments) as a 2D array."""
    import numpy as np
    rows = [line.split() for line in open(path) if line.strip() and not line.startswith("#")]
    return np.array([[float(v) for v in r] for r in rows])


def read_probes(run_dir):
    """(path, time array, {(kind, vessel, x): column array}) of the p, Q, A and u columns of
    RUN_DIR/probes.csv (hemotree_io.read_probes), with at least three samples."""
    path = Path(run_dir) / "probes.csv"
    if not path.is_file():
        raise InputProblem(f"{path} not found")
    try:
        frame = hemotree_io.read_probes(path)
    except (hemotree_io.FormatError, hemotree_io.MissingDependency) as e:
        raise InputProblem(str(e)) from None
    if len(frame.columns) == 0:
        raise InputProblem(f"{path}: empty")
    if len(frame) < 3:
        raise InputProblem(f"{path}: expected rows of {len(frame.columns)} numbers under the header")
    columns = {}
    for j, name in enumerate(frame.columns):
        parsed = hemotree_io.parse_probe_name(name) if j else None
        if parsed and parsed[0] in ("p", "Q", "A", "u"):
            columns[parsed[:3]] = frame.iloc[:, j].to_numpy(dtype=float)
    return path, frame.iloc[:, 0].to_numpy(dtype=float), columns


def probe_column(probes, kind, vessel, x, path):
    """The column of KIND at the probe (VESSEL, X) of read_probes' dict; InputProblem naming
    the probes there if there is none."""
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
    """VALUES at times T interpolated, periodically with PERIOD, at the phases PHASE_AT."""
    import numpy as np
    return np.interp(phase_at, np.mod(t, period), values, period=period)


def compare_location(t_ours, p_ours, q_ours, ref, period, where):
    """The measures of ours (t, p, q) against a reference table (t, P [kPa], Q [ml/s]) over
    the last cycle, and the aligned curves: (measures, curves)."""
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
