"""Figures shared by the scripts (scripts/plot-results, scripts/plot-tree-stats): drawn from
what hemotree_io reads, never reading files of their own but probes.csv (through hemotree_io).
matplotlib is imported where a figure is drawn, so that importing this module costs nothing.

Per-generation statistics of a tree (`vstats --json`), like the paper's Figure 4 (a, c, d):
  plot_tree_stats          vessels by class and per generation, diameter quartiles; several
                           trees (seeds) overlaid, the first drawn full, the others faint

Red cells and tracers carried by a hemosolve run (docs/transport.md), drawn by
scripts/plot-results into DIR/figures when the run has them (plot_all):
  hematocrit-vs-diameter   each vessel's cycle-mean discharge and tube hematocrit against its
                           diameter, with the binned medians, the feed's hematocrit and the
                           Fahraeus law's tube hematocrit at it (Pries et al. 1992)
  capillary-hematocrit     the distribution of discharge hematocrit over the capillaries
                           (class capillary, or vessels under 10 um where no class is given)
  transit-NAME             tracer NAME's mean transit time against diameter and by generation
  curves-NAME              tracer NAME's concentration against time at every probe
                           (probes.csv: indicator-dilution curves)
"""
import math
from pathlib import Path

import hemotree_io

TREE_STATS_CLASSES = [("small_artery", "small arteries", "tab:green"),
                      ("arteriole", "arterioles", "tab:blue"),
                      ("capillary", "capillaries", "tab:red")]


def plot_tree_stats(runs, stem):
    """Writes STEM.png and STEM.svg: per-generation statistics of one or more trees (RUNS:
    `vstats --json` dicts, hemotree_io.read_network_stats), the first in full, the others
    faint. The numbers come from vstats; nothing is recomputed."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    ax_class, ax_total, ax_diam = axes
    for i, stats in enumerate(runs):
        gens = stats["generations"]
        g = [row["generation"] for row in gens]
        alpha = 1.0 if i == 0 else 0.35
        for key, label, colour in TREE_STATS_CLASSES:
            ax_class.semilogy(g, [row["classes"][key] for row in gens], color=colour,
                              alpha=alpha, label=label if i == 0 else None)
        ax_total.semilogy(g, [row["vessels"] for row in gens], color="tab:green",
                          alpha=alpha, label="vessels per generation" if i == 0 else None)
    peak = max(row["vessels"] for stats in runs for row in stats["generations"])
    g_line = [k for k in range(64) if 2.0**k <= 10 * peak]
    ax_total.semilogy(g_line, [2.0**k for k in g_line], color="grey",
                      linestyle="--", label="$2^g$ (full binary growth)")

    # Diameter quartiles of the first run, as boxes without whiskers beyond min/max.
    gens = runs[0]["generations"]
    boxes = [{"med": r["diameter"]["median"] * 1e6, "q1": r["diameter"]["q1"] * 1e6,
              "q3": r["diameter"]["q3"] * 1e6, "whislo": r["diameter"]["min"] * 1e6,
              "whishi": r["diameter"]["max"] * 1e6, "label": str(r["generation"])}
             for r in gens if r["vessels"] > 0]
    ax_diam.bxp(boxes, showfliers=False)
    ax_diam.set_yscale("log")
    ax_diam.set_xticks(range(1, len(boxes) + 1, 5))
    ax_diam.set_xticklabels([b["label"] for b in boxes][::5])

    ax_class.set(xlabel="generation", ylabel="vessels", title="(a) vessels by class",
                 ylim=(0.5, None))
    ax_class.legend()
    ax_total.set(xlabel="generation", ylabel="vessels",
                 title="(c) vessels per generation", ylim=(0.5, None))
    ax_total.legend()
    ax_diam.set(xlabel="generation", ylabel="diameter [um]",
                title="(d) diameter quartiles, min and max")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{runs[0]['vessels']:,} vessels" +
                 (f" (first of {len(runs)} trees; others faint)" if len(runs) > 1 else ""))
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(f"{stem}.{ext}", dpi=120)


UM_PER_M = 1e6


def fahraeus_tube(hd, d_um, scale=1.0):
    """H_T from H_D in a tube of d_um micrometres (Pries, Neuhaus & Gaehtgens 1992, eq. 7;
    physics/phase_separation.hpp), the diameter scaled by the red cells' size as the run did."""
    d_um *= scale
    x = 1 + 1.7 * math.exp(-0.415 * d_um) - 0.6 * math.exp(-0.011 * d_um)
    return hd * (hd + (1 - hd) * x)


def feed_hematocrit(run):
    """The hematocrit blood enters the network with: its inflowing boundaries' (summary.json
    "boundaries"), weighted by their mean inflow; None where the summary has none."""
    flow = cells = 0.0
    for b in run.summary.get("boundaries", []) or []:
        if not isinstance(b, dict):
            continue
        q, h = b.get("flow"), b.get("hematocrit")
        if isinstance(q, (int, float)) and isinstance(h, (int, float)) and q > 0:
            flow += q
            cells += q * h
    return cells / flow if flow > 0 else None


def plot_hematocrit(run, out, written, save, scatter_by_class, binned_median, note):
    import matplotlib.pyplot as plt
    import numpy as np
    stem = "hematocrit-vs-diameter"
    if not run.has("discharge_hematocrit"):
        note(f"no discharge_hematocrit in {run.folder} (--red-cells transport or --steady --red-cells "
             f"transport); skipping {stem}")
        return
    d, hd, ht = run.diameter_um, run.field("discharge_hematocrit"), run.field("tube_hematocrit")
    ok = np.isfinite(hd) & (d > 0)
    fig, ax = plt.subplots(figsize=(7, 5))
    scatter_by_class(ax, run, d, hd, ok)
    edges = np.geomspace(max(d[ok].min(), 1e-3), d[ok].max() * 1.0001, 12)
    centre, median = binned_median(d[ok], hd[ok], edges)
    ax.plot(centre, median, "k-", lw=2, label="discharge: binned median")
    okt = ok & np.isfinite(ht)
    if okt.any():
        centre_t, median_t = binned_median(d[okt], ht[okt], edges)
        ax.plot(centre_t, median_t, "k--", lw=2, label="tube: binned median")
    feed = feed_hematocrit(run)
    if feed is not None:
        grid = np.geomspace(d[ok].min(), d[ok].max(), 200)
        mcv = run.summary.get("mean_cell_volume")
        scale = (92e-18 / mcv) ** (1 / 3) if isinstance(mcv, (int, float)) and mcv > 0 else 1.0
        ax.axhline(feed, color="tab:gray", lw=1, label=f"feed H_D {feed:.2f}")
        ax.plot(grid, [fahraeus_tube(feed, x, scale) for x in grid], color="tab:orange", lw=2,
                label="Fahraeus law: tube H_T at the feed's H_D")
    ax.set_xscale("log")
    ax.set_xlabel("diameter [um]")
    ax.set_ylabel("hematocrit")
    ax.set_ylim(0, max(1.0, float(np.nanmax(hd[ok])) * 1.05))
    steady = run.summary.get("mode") == "steady"
    ax.set_title(("steady" if steady else "cycle-mean") + " discharge hematocrit against diameter")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, out, stem, written)


def plot_capillary_hematocrit(run, out, written, save, note):
    import matplotlib.pyplot as plt
    import numpy as np
    stem = "capillary-hematocrit"
    if not run.has("discharge_hematocrit"):
        return
    hd = run.field("discharge_hematocrit")
    classes = np.array([c if isinstance(c, str) else "" for c in run.classes])
    capillary = classes == "capillary"
    which = "capillaries"
    if not capillary.any():
        capillary = run.diameter_um < 10
        which = "vessels under 10 um"
    sel = capillary & np.isfinite(hd)
    if not sel.any():
        note(f"no capillaries (or vessels under 10 um) in {run.folder}; skipping {stem}")
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.hist(hd[sel], bins=40, range=(0, max(1.0, float(hd[sel].max()))), color="tab:red", alpha=0.8)
    mean, sd = float(np.mean(hd[sel])), float(np.std(hd[sel]))
    ax.axvline(mean, color="k", lw=1.5, label=f"mean {mean:.3f}, SD {sd:.3f}, CV {sd / mean if mean else 0:.2f}")
    ax.set_xlabel("discharge hematocrit")
    ax.set_ylabel(f"{which} ({int(sel.sum())})")
    ax.set_title("distribution of the hematocrit over the capillaries")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, out, stem, written)


def tracer_names(run):
    tracers = run.summary.get("tracers")
    return [t["name"] for t in tracers if isinstance(t, dict) and isinstance(t.get("name"), str)] \
        if isinstance(tracers, list) else []


def plot_transit(run, name, out, written, save, scatter_by_class, note):
    import matplotlib.pyplot as plt
    import numpy as np
    stem = f"transit-{name}"
    mtt = run.field(f"{name}_mean_transit_time")
    d = run.diameter_um
    ok = np.isfinite(mtt) & (d > 0)
    if not ok.any():
        note(f"tracer {name} reached no vessel's curve; skipping {stem}")
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    scatter_by_class(left, run, d, mtt, ok)
    left.set_xscale("log")
    left.set_xlabel("diameter [um]")
    left.set_ylabel("mean transit time [s]")
    left.set_title(f"{name}: mean transit time against diameter")
    left.legend(fontsize=8)
    generation = run.field("generation")
    okg = ok & np.isfinite(generation)
    if okg.any():
        gens = np.unique(generation[okg]).astype(int)
        data = [mtt[okg & (generation == g)] for g in gens]
        right.boxplot(data, positions=gens, widths=0.6, showfliers=False)
        step = max(1, len(gens) // 12)
        right.set_xticks(gens[::step])
        right.set_xticklabels([str(g) for g in gens[::step]])
    right.set_xlabel("generation")
    right.set_ylabel("mean transit time [s]")
    right.set_title("by generation")
    fig.tight_layout()
    save(fig, out, stem, written)


def plot_curves(run, name, out, written, save, note):
    import matplotlib.pyplot as plt
    stem = f"curves-{name}"
    path = Path(run.folder) / "probes.csv"
    if not path.is_file():
        note(f"no {path} (--probe); skipping {stem}")
        return
    probes = hemotree_io.read_probes(path)
    if len(probes) < 1:
        return
    header = list(probes.columns)
    columns = [j for j, h in enumerate(header) if h.startswith(f"c_{name} vessel ")]
    if not columns:
        note(f"no c_{name} column in {path}; skipping {stem}")
        return
    t = probes.iloc[:, 0].to_numpy(dtype=float)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for j in columns:
        label = header[j][len(f"c_{name} "):]
        ax.plot(t, probes.iloc[:, j].to_numpy(dtype=float), lw=1.5, label=label)
    ax.set_xlabel("t [s]")
    unit = header[columns[0]]
    ax.set_ylabel(f"{name} concentration {unit[unit.find('['):] if '[' in unit else ''}")
    ax.set_title(f"{name}: indicator-dilution curves at the probes")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, out, stem, written)


def plot_all(run, out, written, save, scatter_by_class, binned_median, note):
    plot_hematocrit(run, out, written, save, scatter_by_class, binned_median, note)
    plot_capillary_hematocrit(run, out, written, save, note)
    for name in tracer_names(run):
        plot_transit(run, name, out, written, save, scatter_by_class, note)
        plot_curves(run, name, out, written, save, note)
