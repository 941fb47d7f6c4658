#!/usr/bin/env python3
"""What an openBF model's outlets and mean inflow give, computed from the YAML alone.

usage: examples/openbf/steady_check.py MODEL.yaml [--as-documented] [--outlets]

Independent of hemotree's C++ (it reads the YAML with PyYAML and solves the network here), so
that docs/validation.md can set hemosolve's steady pressure beside a hand calculation:

- each two-element Windkessel (R1 and Cc, no R2): the vessel's characteristic impedance
  Z = rho c0 / A0, c0^2 = 2 E h0 / (3 rho R) (openBF's thin wall, Poisson ratio 1/2), h0 the
  file's or openBF's law h0 = R (0.2802 e^(-505.3 R) + 0.1324 e^(-11.14 R)); the total
  resistance as openBF's code builds it, R1 + (R1 - Z) = 2 R1 - Z, or as documented, R1;
- the friction coefficient 2 pi (gamma + 2) mu, gamma from "gamma_profile" (openBF 2.x's code
  reads no "gamma profile") or 2, and each vessel's Poiseuille resistance
  2 (gamma + 2) mu L / (pi R^4) at its radius (Rp as coded, the mean of the linear taper's
  1/R^4 as documented);
- the mean inflow over openBF's reading of the inlet table (the first pair of rows enclosing t);
- the steady pressures of the rigid network with those resistances, outlets to 0 Pa: the
  pressure at the inlet node, and the rougher Q / sum(1 / R_outlet).
"""
import math
import os
import sys

import yaml

MMHG = 133.322387415


def wall(radius, vessel):
    if "h0" in vessel:
        return vessel["h0"]
    return radius * (0.2802 * math.exp(-505.3 * radius) + 0.1324 * math.exp(-11.14 * radius))


def openbf_mean_flow(rows):
    """The mean of openBF's reading: pieces of the rows' chain that reach past the latest time."""
    latest, integral = rows[0][0], 0.0
    for (t0, q0), (t1, q1) in zip(rows, rows[1:]):
        if t1 > latest:
            # the piece of the line through (t0, q0), (t1, q1) from `latest` to t1
            qa = q0 + (latest - t0) * (q1 - q0) / (t1 - t0)
            integral += 0.5 * (qa + q1) * (t1 - latest)
            latest = t1
    return integral / rows[-1][0]


def solve(n, matrix, rhs):
    """Gaussian elimination with partial pivoting (n is small)."""
    a = [row[:] + [b] for row, b in zip(matrix, rhs)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[p] = a[p], a[c]
        for r in range(c + 1, n):
            f = a[r][c] / a[c][c]
            for k in range(c, n + 1):
                a[r][k] -= f * a[c][k]
    x = [0.0] * n
    for r in reversed(range(n)):
        x[r] = (a[r][n] - sum(a[r][k] * x[k] for k in range(r + 1, n))) / a[r][r]
    return x


def main():
    args = sys.argv[1:]
    documented = "--as-documented" in args
    show_outlets = "--outlets" in args
    path = [a for a in args if not a.startswith("--")][0]
    model = yaml.safe_load(open(path))
    rho, mu = model["blood"]["rho"], model["blood"]["mu"]
    vessels = model["network"]
    inlet = model.get("inlet_file", f"{model.get('project_name', '')}_inlet.dat")
    inlet = os.path.join(os.path.dirname(path), inlet)
    rows = [tuple(map(float, line.split()[:2])) for line in open(inlet) if line.strip()]
    q_mean = openbf_mean_flow(rows)

    gammas = {v.get("gamma_profile", v.get("gamma profile") if documented else None) or 2 for v in vessels}
    (gamma,) = gammas
    friction = 2 * math.pi * (gamma + 2) * mu

    nodes = sorted({v["sn"] for v in vessels} | {v["tn"] for v in vessels})
    index = {node: k for k, node in enumerate(nodes)}
    n = len(nodes)
    g = [[0.0] * n for _ in range(n)]
    leaving = {v["sn"] for v in vessels}
    outlets = []
    for v in vessels:
        rp = v.get("Rp", v.get("R0"))
        rd = v.get("Rd", rp) if documented else rp
        # int dx / R(x)^4 for a radius linear from rp to rd
        inv_r4 = 1 / rp**4 if rd == rp else (1 / rp**3 - 1 / rd**3) / (3 * (rd - rp))
        resistance = friction / math.pi**2 * v["L"] * inv_r4
        a, b = index[v["sn"]], index[v["tn"]]
        for i, j, s in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            g[i][j] += s / resistance
        if v["tn"] not in leaving:
            r1 = v["R1"]
            if v.get("R2", 0.0):
                z, total = float("nan"), r1 + v["R2"]
            else:
                h = wall(rd, v)
                c0 = math.sqrt(2 * v["E"] * h / (3 * rho * rd))
                z = rho * c0 / (math.pi * rd * rd)
                total = r1 if documented else 2 * r1 - z
            g[b][b] += 1 / total
            outlets.append((v["label"], r1, z, total))
    rhs = [0.0] * n
    rhs[index[1]] = q_mean
    p = solve(n, g, rhs)

    reading = "as documented" if documented else "as openBF's code computes it"
    print(f"{os.path.basename(path)} {reading}: gamma {gamma}, friction {friction / (math.pi * mu):.0f} pi mu")
    if show_outlets:
        print(f"{'outlet':24s} {'R1':>11s} {'Z':>11s} {'R1 - Z':>11s} {'total':>11s}  [Pa s/m^3]")
        for label, r1, z, total in outlets:
            print(f"{label:24s} {r1:11.4e} {z:11.4e} {r1 - z:11.4e} {total:11.4e}")
    parallel = 1 / sum(1 / total for *_, total in outlets)
    print(f"mean inflow {q_mean * 1e6:.3f} ml/s; outlets in parallel {parallel:.4e} Pa s/m^3")
    print(f"Q / sum(1 / R_outlet) = {q_mean * parallel / MMHG:.1f} mmHg; "
          f"steady pressure at the inlet node {p[index[1]] / MMHG:.1f} mmHg")


if __name__ == "__main__":
    main()
