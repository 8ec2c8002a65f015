#!/usr/bin/env python3
"""Compares two `steadyxr-eval --corpus` runs made with the same options on two devices (say an
NVIDIA GPU and lavapipe): does the other device reproduce the numbers and issue 14's verdicts?

    python3 eval/compare_devices.py A B [--names A_NAME,B_NAME] [--exclude-scenes S1,S2] [--method default]

A and B are each a results.csv, a folder holding one, or a folder of sub-folders each holding one
(a corpus run split by motion, one sub-folder per motion: merged). Prints the rows only one side
has, each method's mean RMSE / none's on both, issue 14's targets for --method side by side, and
the cases where the method's RMSE ratio or shimmer verdict differs between the devices.
--exclude-scenes drops whole scenes, e.g. one that drew a texture one device lacked.
"""
import argparse
import csv
import statistics
import sys
from pathlib import Path

NUMBERS = ["rmse", "temporal_error", "ghost_worst_ratio", "recovery_frames", "recovered", "low_speed"]
# issue 14 (eval/targets.cpp): worst frame <= 1.10x none's, back below none within 3 frames.
WORST_FRAME_LIMIT = 1.10
RECOVERY_LIMIT = 3
# Drivers (sampler precision, rounding) move a case's ratio by a percent or so; more is worth a look.
RATIO_TOLERANCE = 0.02
FEW = 3  # case names printed beside a count


def csv_paths(arg):
    path = Path(arg)
    for one in (path, path / "results.csv"):
        if one.is_file():
            return [one]
    paths = sorted(path.glob("*/results.csv"))  # sorted: the method order stays the same run to run
    if not paths:
        sys.exit(f"{arg}: no results.csv there, nor in its sub-folders")
    return paths


def load(arg, excluded_scenes):
    """(scenario, method) -> that row's scene and numbers, merged over the run's results.csv files."""
    rows = {}
    for path in csv_paths(arg):
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                key = (r["scenario"], r["method"])
                if key in rows:
                    sys.exit(f"{path}: {key} is already in {rows[key]['file']}: overlapping runs?")
                rows[key] = {"file": path, "scene": r["scene"], **{k: float(r[k]) for k in NUMBERS}}
    # dropped after the merge, so a duplicate is caught in an excluded scene too
    return {key: r for key, r in rows.items() if r["scene"] not in excluded_scenes}


def ratio(rows, case, method, field="rmse"):
    return rows[(case, method)][field] / rows[(case, "none")][field]


def few(cases):
    return "" if not cases else ": " + ", ".join(cases[:FEW]) + (", ..." if len(cases) > FEW else "")


def coverage(a, b, names):
    only_a, only_b = sorted(set(a) - set(b)), sorted(set(b) - set(a))
    print(f"[1] rows {names[0]} {len(a)}, {names[1]} {len(b)}; only in {names[0]} {len(only_a)}"
          f"{few([f'{c} {m}' for c, m in only_a])}; only in {names[1]} {len(only_b)}"
          f"{few([f'{c} {m}' for c, m in only_b])}")


def shared_cases(a, b, *methods):
    """The cases both runs hold for all these methods and none (the ratios' denominator)."""
    cases = {c for c, _ in a} & {c for c, _ in b}
    return sorted(c for c in cases if all((c, m) in a and (c, m) in b for m in ("none",) + methods))


def method_means(a, b, names):
    print(f"[2] mean RMSE / none's: {names[0]} | {names[1]} | largest per-case |difference| (case)")
    for m in dict.fromkeys(m for _, m in a):  # A's order
        cases = shared_cases(a, b, m)
        if m == "none" or not cases:
            continue
        diff = {c: abs(ratio(a, c, m) - ratio(b, c, m)) for c in cases}
        worst = max(diff, key=diff.get)
        print(f"    {m:24s} n={len(cases):3d} {statistics.mean(ratio(a, c, m) for c in cases):.4f} | "
              f"{statistics.mean(ratio(b, c, m) for c in cases):.4f} | {diff[worst]:.4f} ({worst})")


def target_counts(rows, cases, m, taas):
    """Issue 14's targets for method m on one device: (label, failing cases or a value) pairs."""
    low = [c for c in cases if rows[(c, m)]["low_speed"]]
    shimmer = [ratio(rows, c, m, "temporal_error") for c in low]
    out = [("mean RMSE above none's", [c for c in cases if ratio(rows, c, m) > 1.0]),
           (f"worst frame > {WORST_FRAME_LIMIT:.2f}x none's",
            [c for c in cases if rows[(c, m)]["ghost_worst_ratio"] > WORST_FRAME_LIMIT]),
           (f"recovery > {RECOVERY_LIMIT} frames or never",
            [c for c in cases if not rows[(c, m)]["recovered"] or rows[(c, m)]["recovery_frames"] > RECOVERY_LIMIT])]
    if len(taas) == 2:
        wins = sum(rows[(c, m)]["rmse"] <= min(rows[(c, t)]["rmse"] for t in taas) for c in cases)
        out.append(("RMSE <= min(taa, taa+jitter)", f"{wins}/{len(cases)}"))
    if taas:
        below = statistics.mean(1 - rows[(c, m)]["rmse"] / rows[(c, "taa")]["rmse"] for c in cases)
        out.append(("mean % below taa", f"{100 * below:.2f} %"))
    out.append(("low-speed TE / none's: median", f"{statistics.median(shimmer):.4f}" if shimmer else "-"))
    out.append(("low-speed TE above none's", f"{sum(s > 1.0 for s in shimmer)} of {len(low)}"))
    return out


def targets(a, b, names, m):
    # The taa comparisons where both runs have taa's rows, on the same cases as every other target.
    taas = next(t for t in (("taa", "taa+jitter"), ("taa",), ()) if shared_cases(a, b, m, *t))
    cases = shared_cases(a, b, m, *taas)
    print(f"[3] issue-14 targets for {m}, {len(cases)} cases: {names[0]} | {names[1]}")
    for (label, va), (_, vb) in zip(target_counts(a, cases, m, taas), target_counts(b, cases, m, taas)):
        if isinstance(va, list):  # failing cases: count them, name a few
            print(f"    {label:32s} {len(va)} | {len(vb)}{few(sorted(set(va) | set(vb)))}")
        else:
            print(f"    {label:32s} {va} | {vb}")


def differences(a, b, names, m):
    cases = shared_cases(a, b, m)
    change = {c: ratio(a, c, m) / ratio(b, c, m) - 1 for c in cases}
    apart = sorted((c for c in cases if abs(change[c]) > RATIO_TOLERANCE), key=lambda c: -abs(change[c]))
    print(f"[4] {m}'s RMSE / none's differs by > {100 * RATIO_TOLERANCE:g} %: {len(apart)} of {len(cases)} cases")
    for c in apart[:FEW]:
        print(f"      {c}: {ratio(a, c, m):.4f} | {ratio(b, c, m):.4f} ({100 * change[c]:+.2f} %)")
    low = [c for c in cases if a[(c, m)]["low_speed"] and b[(c, m)]["low_speed"]]
    flips = [c for c in low if (ratio(a, c, m, "temporal_error") > 1.0) != (ratio(b, c, m, "temporal_error") > 1.0)]
    print(f"    shimmer verdict (TE above none's) differs: {len(flips)} of {len(low)} low-speed cases")
    for c in flips:
        print(f"      {c}: {ratio(a, c, m, 'temporal_error'):.4f} | {ratio(b, c, m, 'temporal_error'):.4f}")


def main(argv):
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
        usage="%(prog)s A B [--names A_NAME,B_NAME] [--exclude-scenes S1,S2] [--method default]")
    p.add_argument("a", metavar="A", help="the first device's run")
    p.add_argument("b", metavar="B", help="the second device's run")
    p.add_argument("--names", default="A,B", help="the two devices' names, comma-separated")
    p.add_argument("--exclude-scenes", default="", help="scenes (the scene column) left out of everything")
    p.add_argument("--method", default="default", help="the method whose targets and differences to show")
    args = p.parse_args(argv)
    names = args.names.split(",")
    if len(names) != 2:
        p.error("--names takes two names, A_NAME,B_NAME")
    excluded = set(filter(None, args.exclude_scenes.split(",")))
    a, b = load(args.a, excluded), load(args.b, excluded)
    coverage(a, b, names)
    method_means(a, b, names)
    if not shared_cases(a, b, args.method):
        sys.exit(f"no case has {args.method} and none in both runs")
    targets(a, b, names, args.method)
    differences(a, b, names, args.method)


if __name__ == "__main__":
    main(sys.argv[1:])
