#!/usr/bin/env python3
"""Plans random goals nobody chose, and reports how many plans finish.

Each case is a random window of a shared DEM or a random view of a shared
mesh (an up axis and a window of its top view), at a random array size of the
paper's Table 1, planned by `hapticjam plan --json`. A case finishes when the
command exits 0 with a plan (a settle that has no equilibrium is refused
inside the plan, not a failure). Seeded: the same --seed gives the same cases.

  scripts/random_goals.py --cases 100 --seed 1 --planner algorithm2 --out /tmp/rg --report docs/random-goals.md
"""
import argparse
import concurrent.futures
import json
import os
import random
import subprocess
import sys
import time

TABLE1 = [(1, 2), (2, 3), (3, 4), (3, 5), (4, 5), (4, 6), (5, 6), (5, 7), (5, 8), (6, 7), (6, 8), (6, 9),
          (7, 9), (7, 10), (8, 11), (9, 12)]
AXES = ["x", "y", "z", "-x", "-y", "-z"]


def goal_files(shared):
    dems = sorted(os.path.join(shared, "data/dem", f) for f in os.listdir(os.path.join(shared, "data/dem"))
                  if f.endswith(".csv"))
    meshes = sorted(os.path.join(shared, "data/mesh", f) for f in os.listdir(os.path.join(shared, "data/mesh"))
                    if f.endswith(".stl"))
    return dems, meshes


def random_window(rng):
    """A window of at least a third of each side, as fractions x0,y0,x1,y1."""
    w, h = rng.uniform(0.35, 1.0), rng.uniform(0.35, 1.0)
    x0, y0 = rng.uniform(0.0, 1.0 - w), rng.uniform(0.0, 1.0 - h)
    return f"{x0:.3f},{y0:.3f},{x0 + w:.3f},{y0 + h:.3f}"


def make_cases(n, seed, shared):
    rng = random.Random(seed)
    dems, meshes = goal_files(shared)
    cases = []
    for k in range(n):
        rows, cols = rng.choice(TABLE1)
        if rng.random() < 0.5:
            goal, extra = rng.choice(dems), []
        else:
            goal, extra = rng.choice(meshes), ["--up-axis", rng.choice(AXES)]
        cases.append({"case": k, "goal": goal, "rows": rows, "cols": cols,
                      "args": ["--region", random_window(rng)] + extra})
    return cases


def run_case(cli, case, planner, out, timeout_s):
    d = os.path.join(out, f"case{case['case']:03d}")
    cmd = [cli, "plan", case["goal"], "--rows", str(case["rows"]), "--cols", str(case["cols"]), "--out", d,
           "--json", "--planner", planner] + case["args"]
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
        seconds = time.monotonic() - start
        if p.returncode != 0:
            return dict(case, status="failed", seconds=seconds, detail=p.stderr.strip()[-300:])
        summary = json.loads(p.stdout.strip().splitlines()[-1])
        return dict(case, status="ok", seconds=seconds, correlation=summary.get("correlation"),
                    steps=summary.get("steps"), refused=summary.get("refused", 0))
    except subprocess.TimeoutExpired:
        return dict(case, status="timeout", seconds=time.monotonic() - start, detail=f"over {timeout_s} s")


def report(results, args):
    ok = [r for r in results if r["status"] == "ok"]
    corr = [r["correlation"] for r in ok if r.get("correlation") is not None]
    lines = [
        "# Random goals: do plans finish on inputs nobody chose?",
        "",
        "Made by `scripts/random_goals.py`: random windows of the shared DEMs and random views (up axis and",
        "window) of the shared meshes, at random Table 1 sizes, each planned by `hapticjam plan`.",
        "",
        f"Command: `scripts/random_goals.py --cases {args.cases} --seed {args.seed} --planner {args.planner} "
        f"--jobs {args.jobs}`",
        "",
        f"- finished plans: **{len(ok)} of {len(results)}** ({100.0 * len(ok) / max(1, len(results)):.0f} %)",
    ]
    if corr:
        worst = min(ok, key=lambda r: r["correlation"] if r.get("correlation") is not None else 2)
        lines.append(f"- correlation (Eq. 12): mean {sum(corr) / len(corr):.3f}, worst {min(corr):.3f} "
                     f"(case {worst['case']}: {os.path.basename(worst['goal'])} at {worst['rows']} x {worst['cols']})")
    lines.append(f"- plans with refused actions (dead ends): {sum(1 for r in ok if r.get('refused'))}")
    slowest = max(results, key=lambda r: r["seconds"])
    lines.append(f"- time per plan: mean {sum(r['seconds'] for r in results) / len(results):.1f} s, slowest "
                 f"{slowest['seconds']:.1f} s ({os.path.basename(slowest['goal'])} at {slowest['rows']} x {slowest['cols']})")
    lines += ["", "| case | goal | size | window / view | status | correlation | steps | refused | s |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        c = r.get("correlation")
        lines.append(f"| {r['case']} | {os.path.basename(r['goal'])} | {r['rows']} x {r['cols']} | "
                     f"{' '.join(r['args'])} | {r['status']} | {'' if c is None else f'{c:.3f}'} | "
                     f"{r.get('steps', '')} | {r.get('refused', '')} | {r['seconds']:.1f} |")
    failed = [r for r in results if r["status"] != "ok"]
    if failed:
        lines += ["", "Not finished:"] + [f"- case {r['case']}: {r.get('detail', '')}" for r in failed]
    return "\n".join(lines) + "\n"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=100)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--planner", default="algorithm2")
    ap.add_argument("--jobs", type=int, default=2, help="plans at once")
    ap.add_argument("--timeout-s", type=float, default=600.0, help="per plan")
    ap.add_argument("--cli", default=os.path.join(here, "..", "build", "hapticjam"))
    ap.add_argument("--shared", default=os.path.join(here, "..", "..", "shared"))
    ap.add_argument("--out", default="/tmp/hj-random-goals")
    ap.add_argument("--report", help="write the markdown report here (default: stdout)")
    args = ap.parse_args()
    if args.cases < 1:
        ap.error("--cases must be at least 1")
    cases = make_cases(args.cases, args.seed, args.shared)
    results = [None] * len(cases)
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_case, args.cli, c, args.planner, args.out, args.timeout_s): c["case"] for c in cases}
        for done, f in enumerate(concurrent.futures.as_completed(futures), 1):
            r = f.result()
            results[r["case"]] = r
            print(f"random_goals: {done}/{len(cases)} case {r['case']} {r['status']} {r['seconds']:.1f} s",
                  file=sys.stderr, flush=True)
    text = report(results, args)
    if args.report:
        with open(args.report, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0 if all(r["status"] == "ok" for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
