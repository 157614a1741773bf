#!/usr/bin/env python3
"""Where the remaining error of plans lies, per goal kind (terrain, CAD part).

Plans every shared DEM (terrain) and mesh (CAD part) at each size with
`hapticjam plan` and averages plan.json's `error_breakdown` per kind: the
share of the residual at the clamped edge, near valleys between nodes, in
detail smaller than a cell, and elsewhere, beside each place's share of the
area (src/metrics/error_breakdown.h says how points are placed).

  scripts/error_places.py --sizes 3x4,6x8,9x12 --planner algorithm2 --report FILE.md
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

PLACES = ["clamped_edge", "valley_between_nodes", "sub_cell_detail", "elsewhere"]


def goals(shared):
    out = []
    for sub, kind, exts in (("dem", "terrain", (".csv", ".tif")), ("mesh", "CAD part", (".stl", ".obj"))):
        folder = os.path.join(shared, "data", sub)
        out += [(os.path.join(folder, f), kind) for f in sorted(os.listdir(folder)) if f.endswith(exts)]
    return out


def plan(cli, goal, rows, cols, planner, out):
    d = os.path.join(out, f"{os.path.basename(goal)}-{rows}x{cols}-{planner}")
    cmd = [cli, "plan", goal, "--rows", str(rows), "--cols", str(cols), "--planner", planner, "--out", d, "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()[-200:]
    with open(os.path.join(d, "plan.json")) as f:
        doc = json.load(f)
    return doc, ""


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="3x4,6x8,9x12")
    ap.add_argument("--planner", default="algorithm2")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--cli", default=os.path.join(here, "..", "build", "hapticjam"))
    ap.add_argument("--shared", default=os.path.join(here, "..", "..", "shared"))
    ap.add_argument("--out", default="/tmp/hj-error-places")
    ap.add_argument("--report", help="markdown file (default: stdout)")
    args = ap.parse_args()
    sizes = [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    cases = [(g, k, r, c) for (g, k) in goals(args.shared) for (r, c) in sizes]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        docs = list(pool.map(lambda case: plan(args.cli, case[0], case[2], case[3], args.planner, args.out), cases))
    lines = [f"Command: `scripts/error_places.py --sizes {args.sizes} --planner {args.planner}`", "",
             "| kind | size | plans | mean r | " + " | ".join(f"{p} error / area" for p in PLACES) + " | dominant (count) |",
             "|---|---|---|---|" + "---|" * len(PLACES) + "---|"]
    failed = []
    for kind in ("terrain", "CAD part"):
        for (r, c) in sizes:
            rows = [(case, doc) for case, (doc, err) in zip(cases, docs) if case[1] == kind and case[2:] == (r, c) and doc]
            failed += [f"{os.path.basename(case[0])} {r}x{c}: {err}" for case, (doc, err) in zip(cases, docs)
                       if case[1] == kind and case[2:] == (r, c) and not doc]
            if not rows:
                continue
            corr = [d["correlation"] for _, d in rows if d.get("correlation") is not None]
            cells = []
            for p in PLACES:
                e = sum(d["error_breakdown"]["places"][p]["error_share"] for _, d in rows) / len(rows)
                a = sum(d["error_breakdown"]["places"][p]["area_share"] for _, d in rows) / len(rows)
                cells.append(f"{e:.2f} / {a:.2f}")
            dominant = {}
            for _, d in rows:
                dominant[d["error_breakdown"]["dominant"]] = dominant.get(d["error_breakdown"]["dominant"], 0) + 1
            dom = ", ".join(f"{k} ({v})" for k, v in sorted(dominant.items(), key=lambda kv: -kv[1]))
            mean_r = f"{sum(corr) / len(corr):.3f}" if corr else "-"
            lines.append(f"| {kind} | {r} x {c} | {len(rows)} | {mean_r} | " + " | ".join(cells) + f" | {dom} |")
    if failed:
        lines += ["", "Plans that did not finish:"] + [f"- {f}" for f in failed]
    text = "\n".join(lines) + "\n"
    if args.report:
        with open(args.report, "w") as f:
            f.write(text)
    sys.stdout.write(text)
    return 0 if not failed else 1


if __name__ == "__main__":
    sys.exit(main())
