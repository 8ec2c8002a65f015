#!/usr/bin/env python3
"""Charts from steadyxr-eval's CSV output: python3 eval/plot.py OUT_DIR

Writes OUT_DIR/charts/:
  pareto_<scenario>.png     accuracy (RMSE, MTCD) against cost, one point per method/setting,
                            Pareto front drawn
  timeseries_<scenario>.png MTCD and RMSE per frame (fast-turn, moving-object and pursuit scenarios)
  warp_errors.png           seed 004 error pixels against extrapolation time and head/object speed
  pareto_class_<motion>.png per motion class (corpus runs): mean RMSE and temporal error relative to
                            none's against cost, one point per method
and OUT_DIR/anim/<case>.gif from the frames steadyxr-eval wrote to OUT_DIR/anim/<case>/ (python3-pil).
"""
import csv
import json
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:  # e.g. a pyenv python first on PATH: fall back to Debian's python3-matplotlib
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise

MAIN_METHODS = ["none", "fxaa", "msaa4", "taa", "taa+jitter", "hmtaa", "vtaa", "default", "default+jitter", "oracle",
                "oracle+jitter"]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(v):
    try:
        x = float(v)
        return x if math.isfinite(x) else None
    except (TypeError, ValueError):
        return None


def device_name(out):
    """The Vulkan device the costs were measured on (results.json's config), for the axis label."""
    try:
        with open(os.path.join(out, "results.json")) as f:
            return json.load(f)["config"]["device"]
    except (OSError, ValueError, KeyError):
        return "unknown device"


def pareto(points):
    """Non-dominated points (lower cost and lower error are better), sorted by cost."""
    front, best = [], float("inf")
    for c, e, name in sorted(points):
        if e < best:
            front.append((c, e, name))
            best = e
    return front


def plot_pareto(rows, charts, device):
    for scenario in sorted({r["scenario"] for r in rows}):
        sub = [r for r in rows if r["scenario"] == scenario]
        fig, axes = plt.subplots(1, 2, figsize=(13, 5))
        for ax, metric, label in ((axes[0], "rmse", "RMSE vs ground truth"), (axes[1], "mtcd", "MTCD (8-bit units)")):
            pts = [(num(r["cost_ms"]), num(r[metric]), r["method"]) for r in sub]
            pts = [p for p in pts if p[0] is not None and p[1] is not None]
            for c, e, name in pts:
                sweep = "@" in name
                ax.scatter([c], [e], s=18 if sweep else 36, marker="x" if sweep else "o",
                           color="gray" if sweep else ("tab:red" if name.startswith("default") else "tab:blue"))
                ax.annotate(name, (c, e), fontsize=6, xytext=(3, 2), textcoords="offset points")
            front = pareto(pts)
            if front:
                ax.plot([p[0] for p in front], [p[1] for p in front], "-", color="tab:green", lw=1.2,
                        label="Pareto front")
                ax.legend(fontsize=8)
            if pts and min(p[0] for p in pts) > 0:
                ax.set_xscale("log")
            ax.set_xlabel(f"cost: filter ms + extra render ms (both eyes, {device})")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        fig.suptitle(f"{scenario}: accuracy against cost")
        fig.tight_layout()
        fig.savefig(os.path.join(charts, f"pareto_{scenario}.png"), dpi=110)
        plt.close(fig)


def plot_timeseries(series, charts):
    scenarios = sorted({r["scenario"] for r in series})
    wanted = [s for s in scenarios if "fastturn" in s or s.startswith("moving") or "pursuit" in s] or scenarios[:1]
    wanted = wanted[:8]  # a corpus has dozens; results.csv / timeseries.csv hold them all
    for scenario in wanted:
        sub = [r for r in series if r["scenario"] == scenario]
        fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
        for m in MAIN_METHODS:
            rows = [r for r in sub if r["method"] == m]
            if not rows:
                continue
            t = [num(r["t_s"]) for r in rows]
            axes[0].plot(t, [num(r["mtcd"]) for r in rows], label=m, lw=1)
            axes[1].plot(t, [num(r["rmse"]) for r in rows], label=m, lw=1)
        first = [r for r in sub if r["method"] == sub[0]["method"]] if sub else []
        axes[2].plot([num(r["t_s"]) for r in first], [num(r["head_speed_deg_s"]) for r in first], color="k",
                     label="head speed (deg/s)")
        ax2 = axes[2].twinx()
        ax2.plot([num(r["t_s"]) for r in first], [num(r["object_speed_m_s"]) for r in first], color="tab:orange",
                 label="object speed (m/s)")
        axes[0].set_ylabel("MTCD (8-bit)")
        axes[1].set_ylabel("RMSE vs GT")
        axes[2].set_ylabel("head speed deg/s")
        ax2.set_ylabel("object speed m/s")
        axes[2].set_xlabel("time (s)")
        axes[0].legend(fontsize=8, ncol=4)
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.suptitle(f"{scenario}: per-frame MTCD and RMSE")
        fig.tight_layout()
        fig.savefig(os.path.join(charts, f"timeseries_{scenario}.png"), dpi=110)
        plt.close(fig)


def plot_warp(warp, charts):
    if not warp:
        return
    fig, axes = plt.subplots(1, 2, figsize=(13, 5))
    for si, scenario in enumerate(sorted({r["scenario"] for r in warp})):
        color = plt.cm.tab10(si % 10)
        for mode, style in (("timewarp", "--"), ("depthwarp", "-")):
            sub = [r for r in warp if r["scenario"] == scenario and r["mode"] == mode]
            steps = sorted({int(r["step"]) for r in sub})
            xs, ys = [], []
            for k in steps:
                vals = [num(r["error_pixels"]) for r in sub if int(r["step"]) == k]
                xs.append(num(next(r["extrapolation_ms"] for r in sub if int(r["step"]) == k)))
                ys.append(sum(vals) / len(vals))
            axes[0].plot(xs, ys, style, marker="o", ms=3, color=color, label=f"{scenario} {mode}")
    axes[0].set_xlabel("extrapolation time (ms)")
    axes[0].set_ylabel("error pixels (mean over frames, left eye)")
    axes[0].set_title("seed 004 error pixels vs extrapolation time (dashed: timewarp, solid: depth warp)")
    axes[0].legend(fontsize=6)
    axes[0].grid(alpha=0.3)
    # Against speed: the largest extrapolation step, every frame of every scenario.
    kmax = max(int(r["step"]) for r in warp)
    for mode, color in (("timewarp", "tab:blue"), ("depthwarp", "tab:red")):
        sub = [r for r in warp if r["mode"] == mode and int(r["step"]) == kmax]
        speed = [num(r["head_speed_deg_s"]) + 40.0 * num(r["object_speed_m_s"]) for r in sub]
        axes[1].scatter(speed, [num(r["error_pixels"]) for r in sub], s=6, color=color, alpha=0.5, label=mode)
    axes[1].set_xlabel("head speed (deg/s) + 40 x object speed (m/s)  [~deg/s at 1.5 m]")
    axes[1].set_ylabel(f"error pixels at step {kmax}")
    axes[1].set_title("error pixels vs speed")
    axes[1].legend(fontsize=8)
    axes[1].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(charts, "warp_errors.png"), dpi=110)
    plt.close(fig)


def plot_pareto_classes(rows, charts, device):
    """Corpus: per motion class, each method's mean RMSE and temporal error relative to none's in the
    same case, against its mean cost (the oracle, a CPU bound, at the left edge)."""
    none = {r["scenario"]: r for r in rows if r["method"] == "none"}
    classes = sorted({r.get("motion_class", "") for r in rows} - {""})
    if len(classes) < 2:
        return
    for cls in classes:
        sub = [r for r in rows if r.get("motion_class") == cls and r["scenario"] in none]
        fig, axes = plt.subplots(1, 2, figsize=(13, 5))
        for ax, metric, label in ((axes[0], "rmse", "mean RMSE / none's"),
                                  (axes[1], "temporal_error", "mean temporal error / none's")):
            pts = []
            for m in sorted({r["method"] for r in sub}):
                ratios, costs = [], []
                for r in sub:
                    if r["method"] != m:
                        continue
                    n = num(none[r["scenario"]][metric])
                    v = num(r[metric])
                    if n and v is not None:
                        ratios.append(v / n)
                    costs.append(num(r["cost_ms"]) or 0.0)
                if ratios:
                    pts.append((max(sum(costs) / len(costs), 1e-3), sum(ratios) / len(ratios), m))
            oracles = ("oracle", "oracle+jitter")
            if not any(p[2] not in oracles for p in pts):
                continue
            # The oracles are references, not methods: lines, outside the Pareto front (the
            # unjittered one is no bound where the tremor spreads the samples too little).
            for c, e, name in [p for p in pts if p[2] in oracles]:
                ax.axhline(e, color="tab:purple", lw=0.9, ls=":" if name == "oracle" else "--",
                           label=f"{name} {e:.2f}")
            pts = [p for p in pts if p[2] not in oracles]
            for c, e, name in pts:
                ax.scatter([c], [e], s=36, color="tab:red" if name.startswith("default") else "tab:blue")
                ax.annotate(name, (c, e), fontsize=7, xytext=(3, 2), textcoords="offset points")
            front = pareto(pts)
            if front:
                ax.plot([p[0] for p in front], [p[1] for p in front], "-", color="tab:green", lw=1.2,
                        label="Pareto front")
            ax.legend(fontsize=8)
            ax.axhline(1.0, color="gray", lw=0.8, ls="--")
            ax.set_xscale("log")
            ax.set_xlabel(f"cost: filter ms (both eyes, {device})")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        n_cases = len({r["scenario"] for r in sub})
        fig.suptitle(f"motion class {cls}: {n_cases} cases, accuracy against cost")
        fig.tight_layout()
        fig.savefig(os.path.join(charts, f"pareto_class_{cls}.png"), dpi=110)
        plt.close(fig)


def make_animations(out):
    """anim/<case>/frame_*.png -> anim/<case>.gif (python3-pil), 10 frames per second, looping."""
    anim = os.path.join(out, "anim")
    if not os.path.isdir(anim):
        return
    from PIL import Image  # python3-pil (Debian); imported here so charts never depend on it

    for case in sorted(os.listdir(anim)):
        folder = os.path.join(anim, case)
        if not os.path.isdir(folder):
            continue
        frames = [Image.open(os.path.join(folder, f)).convert("RGB")
                  for f in sorted(os.listdir(folder)) if f.endswith(".png")]
        if frames:
            frames[0].save(os.path.join(anim, case + ".gif"), save_all=True, append_images=frames[1:],
                           duration=100, loop=0)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out"
    charts = os.path.join(out, "charts")
    os.makedirs(charts, exist_ok=True)
    rows = read_csv(os.path.join(out, "results.csv"))
    if os.path.exists(os.path.join(out, "corpus.csv")):
        plot_pareto_classes(rows, charts, device_name(out))  # a corpus: one chart per motion class
    else:
        plot_pareto(rows, charts, device_name(out))
    plot_timeseries(read_csv(os.path.join(out, "timeseries.csv")), charts)
    plot_warp(read_csv(os.path.join(out, "warp_errors.csv")), charts)
    make_animations(out)
    print(f"charts written to {charts}")


if __name__ == "__main__":
    main()
