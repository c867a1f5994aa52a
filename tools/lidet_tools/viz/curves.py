# SPDX-License-Identifier: MIT
"""Precision-recall curves from an evaluation result, and energy histograms (ID vs OOD)."""
from __future__ import annotations

import numpy as np

KEY_COLORS = ["#2ca02c", "#ff7f0e", "#d62728", "#1f77b4", "#9467bd", "#8c564b"]


def plot_pr(result: dict, metric: str = "3d", classes=None, axes=None, figsize=None):
    """One panel per class, one curve per difficulty (KITTI) or distance band (sensor protocol).

    result: the dict returned by ``kitti_ap.evaluate`` / ``boxes_ap.evaluate``. The curve is the
    devkit's: precision (max to the right) at the 41 sampled score thresholds, drawn at the recall
    positions 0, 1/40, ..., 1 they stand for. The legend gives AP|R40 and AP|R11.
    """
    import matplotlib.pyplot as plt

    curves = result["curves"]
    classes = list(classes or curves)
    if axes is None:
        n = len(classes)
        fig, axes = plt.subplots(1, n, figsize=figsize or (4.2 * n, 4.2), dpi=110, squeeze=False,
                                 layout="constrained")
        axes = axes[0]
    else:
        fig = axes[0].figure
    for ax, cls in zip(axes, classes):
        per = curves[cls][metric]
        for k, (key, st) in enumerate(per.items()):
            rpos = np.linspace(0.0, 1.0, len(st["precision"]))
            if st["n_gt"] == 0:
                ax.plot([], [], color=KEY_COLORS[k % len(KEY_COLORS)], label=f"{key}: no ground truth")
                continue
            ax.step(rpos, st["precision"], where="post", color=KEY_COLORS[k % len(KEY_COLORS)], lw=1.6,
                    label=f"{key}: AP|R40 {st['ap_r40']:.1f}, AP|R11 {st['ap_r11']:.1f} (n={st['n_gt']})")
        thr = next(iter(per.values()))["min_overlap"]
        ax.set_title(f"{cls}, {metric.upper()} AP at IoU > {thr:g}")
        ax.set_xlim(0, 1.0)
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("recall")
        ax.set_ylabel("precision")
        ax.grid(True, lw=0.4, alpha=0.6)
        ax.legend(loc="lower left", fontsize=7)
    return fig


def energy_threshold(energy_id, tpr: float = 0.95) -> float:
    """Gate threshold gamma keeping the fraction tpr of in-distribution samples (keep if E < gamma)."""
    return float(np.quantile(np.asarray(energy_id, dtype=np.float64), tpr))


def plot_energy_hist(energy_id, energy_ood, threshold: float | None = None, ax=None, bins: int = 60,
                     labels=("in-distribution (ID)", "out-of-distribution (OOD)"), title=None,
                     unit: str = "energy E = -T log sum exp(f/T)"):
    """Overlaid density histograms of ID and OOD energies with the gate threshold (keep if E < gamma).
    threshold None: gamma at 95 % TPR on the ID energies. Returns the Figure."""
    import matplotlib.pyplot as plt

    e_id = np.asarray(energy_id, dtype=np.float64).ravel()
    e_ood = np.asarray(energy_ood, dtype=np.float64).ravel()
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4), dpi=110, layout="constrained")
    else:
        fig = ax.figure
    allv = np.concatenate([e_id, e_ood])
    edges = np.histogram_bin_edges(allv[np.isfinite(allv)], bins=bins)
    ax.hist(e_id, bins=edges, density=True, alpha=0.55, color="#1f77b4", label=f"{labels[0]}, n={len(e_id)}")
    ax.hist(e_ood, bins=edges, density=True, alpha=0.55, color="#d62728", label=f"{labels[1]}, n={len(e_ood)}")
    gamma = energy_threshold(e_id) if threshold is None else float(threshold)
    tpr = float((e_id < gamma).mean()) if len(e_id) else float("nan")
    fpr = float((e_ood < gamma).mean()) if len(e_ood) else float("nan")
    ax.axvline(gamma, color="black", lw=1.2, ls="--",
               label=f"gate gamma = {gamma:.3g}: keeps {100 * tpr:.1f} % ID, {100 * fpr:.1f} % OOD")
    ax.set_xlabel(unit)
    ax.set_ylabel("density")
    ax.legend(fontsize=8)
    ax.set_title(title or "Energy of ID and OOD proposals (lower = more in-distribution)")
    return fig
