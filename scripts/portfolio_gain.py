#!/usr/bin/env python3
"""The portfolio against Algorithm 2, plan by plan, from two sweep.csv files.

  scripts/portfolio_gain.py ALGORITHM2/sweep.csv PORTFOLIO/sweep.csv

Rows are matched by goal, size and order (the Luxembourg CSV and TIFF are
both "luxembourg_elev"). Prints the mean correlation of each and the mean,
smallest and largest gain, the plans where the portfolio is more than 0.01
below, the portfolio's time over its own Algorithm 2 run's (from its note),
the same against the Algorithm 2 sweep's own rows (both include goal
resampling and scoring) and in total, the strategies it chose, and the mean per size.
"""
import collections
import csv
import re
import statistics
import sys


def keyed(path):
    seen, out = collections.Counter(), {}
    for r in csv.DictReader(open(path)):
        k = (r["goal"], int(r["rows"]), int(r["cols"]))
        out[k + (seen[k],)] = r
        seen[k] += 1
    return out


def chosen_is_plan_so_far(note):
    """True if the note's chosen strategy ("chose NAME; strategies: NAME r in t s ...; ...")
    was stopped at the time budget and its plan so far kept."""
    chosen = note.split(";")[0].removeprefix("chose ")
    entries = [part.strip().removeprefix("strategies: ") for part in note.split(";")[1:]]
    return any(e.startswith(chosen + " ") and "plan so far" in e for e in entries)


def main(a2_path, pf_path):
    a2, pf = keyed(a2_path), keyed(pf_path)
    both = [k for k in pf if k in a2 and a2[k]["status"] == "ok" and pf[k]["status"] == "ok"]
    gain = {k: float(pf[k]["correlation"]) - float(a2[k]["correlation"]) for k in both}
    ratios, chosen, per_size = [], collections.Counter(), collections.defaultdict(list)
    # Whole rows against whole rows (goal resampling and scoring in both), from the two runs.
    row_ratios = [float(pf[k]["seconds"]) / max(float(a2[k]["seconds"]), 1e-3) for k in both]
    for k in both:
        m = re.search(r"algorithm2 -?[0-9.]+ in ([0-9.e+-]+) s", pf[k].get("note", ""))
        if m:
            ratios.append(float(pf[k]["seconds"]) / max(float(m.group(1)), 1e-3))
        chosen[pf[k].get("note", "").split(";")[0].removeprefix("chose ")] += 1
        per_size[k[1:3]].append((float(a2[k]["correlation"]), float(pf[k]["correlation"])))
    print(f"plans compared: {len(both)} (algorithm2 rows {len(a2)}, portfolio rows {len(pf)}; "
          f"portfolio not ok: {sum(r['status'] != 'ok' for r in pf.values())})")
    print(f"mean correlation: algorithm2 {statistics.mean(x for v in per_size.values() for x, _ in v):.3f}, "
          f"portfolio {statistics.mean(y for v in per_size.values() for _, y in v):.3f}")
    print(f"gain: mean {statistics.mean(gain.values()):.3f}, smallest {min(gain.values()):.4f}, "
          f"largest {max(gain.values()):.3f}")
    below = sorted((g, k) for k, g in gain.items() if g < -0.01)
    print(f"portfolio more than 0.01 below algorithm2: {len(below)} {below}")
    if ratios:
        print(f"portfolio time / its algorithm2's: median {statistics.median(ratios):.2f}, largest {max(ratios):.2f}")
    pf_total, a2_total = (sum(float(rows[k]["seconds"]) for k in both) for rows in (pf, a2))
    print(f"total time: portfolio {pf_total:.0f} s, algorithm2 sweep {a2_total:.0f} s: {pf_total / a2_total:.2f} x")
    worst = max(zip(row_ratios, both))
    print(f"portfolio row time / algorithm2 sweep row time: median {statistics.median(row_ratios):.2f}, "
          f"largest {worst[0]:.2f} ({worst[1][0]} {worst[1][1]}x{worst[1][2]})")
    print("chosen:", ", ".join(f"{name} {n}" for name, n in chosen.most_common()))
    notes = [pf[k].get("note", "") for k in both]
    stopped = sum("stopped at the time budget" in n for n in notes)
    so_far = sum(chosen_is_plan_so_far(n) for n in notes)
    print(f"plans where the budget stopped a strategy: {stopped}; chosen plans that are a stopped strategy's plan so far: {so_far}")
    print("| size | algorithm2 mean r | portfolio mean r |")
    print("|---|---|---|")
    for s in sorted(per_size):
        v = per_size[s]
        print(f"| {s[0]}x{s[1]} | {statistics.mean(x for x, _ in v):.3f} | {statistics.mean(y for _, y in v):.3f} |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
