#!/usr/bin/env python3
"""Where a sweep's time goes, per array size, as a Markdown table.

  scripts/sweep_times.py SWEEP.csv

From `hapticjam sweep`'s sweep.csv: per size, the seconds of all its plans,
of the settles they kept (`settle_seconds`) and of the dead ends they refused
(`refused_seconds`), and the slowest plan; then the totals.
"""
import collections
import csv
import sys


def main(path):
    rows = list(csv.DictReader(open(path)))
    by_size = collections.OrderedDict()
    for r in sorted(rows, key=lambda r: (int(r["rows"]) * int(r["cols"]), int(r["rows"]))):
        by_size.setdefault(f"{r['rows']}x{r['cols']}", []).append(r)

    def line(label, value):
        return f"| {label} | " + " | ".join(value(plans) for plans in by_size.values()) + " |"

    total = lambda key: lambda plans: f"{sum(float(p[key]) for p in plans):.1f}"
    print("| size | " + " | ".join(by_size) + " |")
    print("|---|" + "---|" * len(by_size))
    print(line(f"all {len(next(iter(by_size.values())))} plans, s", total("seconds")))
    print(line("kept settles, s", total("settle_seconds")))
    print(line("refused settles, s", total("refused_seconds")))
    print(line("slowest plan, s", lambda plans: f"{max(float(p['seconds']) for p in plans):.1f}"))
    s = lambda key: sum(float(r[key]) for r in rows)
    print(f"\nAll {len(rows)}: {s('seconds'):.0f} s, {s('settle_seconds'):.0f} s of it in kept settles and "
          f"{s('refused_seconds'):.0f} s in refused ones; {sum(int(r['refused']) for r in rows)} refused steps.")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
