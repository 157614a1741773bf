#!/usr/bin/env python3
"""The table of scripts/synth_effects.sh: one row per synthetic dataset, from
WORK/CASE/data/truth.json (the true model), WORK/CASE/compare/summary.json
(the data against the baseline model) and WORK/CASE/diagnose/diagnosis.json.

usage: synth_effects_table.py WORK SESSIONS CASE [CASE ...]
"""
import json
import math
import os
import sys


def bic_text(value):
    """delta BIC as the table shows it; a candidate not refitted (outrun by a
    refitted one, judged on its scan) has none (null in diagnosis.json)."""
    return "n/a" if value is None else "%.0f" % value


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def g(v):
    return "%.4g" % v


# The effects written only for the test (tests/tools/offform_effects.cc) and
# the candidate diagnose should choose for each; none for the camera bump,
# which no candidate has: its data should stay unexplained.
NEAREST = {"test_power_stiffening": ["stiffening"], "test_interior_contraction": ["jam_contraction"],
           "test_soft_interior": ["cell_defect"], "test_camera_bump": []}


def expected_verdict(truth):
    out = set()
    for effect in truth.get("effects", {}):
        out.update(NEAREST.get(effect, [effect]))
    return sorted(out)


# diagnose counts an RMSE within this share of the noise floor as explained
# (GoodnessOfFitOptions::floor_tolerance): an effect that moves the frames
# less than that, against the true baseline, is not in the data to be found,
# so "none" is as right a verdict as the effect itself.
FLOOR_TOLERANCE = 0.05


def undetectable(summary):
    return summary is not None and summary["rmse_mm"] <= (1.0 + FLOOR_TOLERANCE) * summary["noise_floor_mm"]


def true_values(truth):
    out = []
    for effect, params in sorted(truth.get("effects", {}).items()):
        for name, value in sorted(params.items()):
            out.append((effect, name, value))
    return out


def fitted_value(diag, effect, name):
    """The parameter as the chosen model fitted it, else as the candidate's
    refit (or, if screened out, its prediction) on the baseline had it."""
    final = diag.get("final_params", {}).get("effects", {})
    if effect in final and name in final[effect]:
        return final[effect][name], ""
    for c in diag.get("ranking", []):
        if c["effect"] == effect:
            v = c["params"].get("effects", {}).get(effect, {}).get(name)
            if v is not None:
                return v, " (predicted, not chosen)" if c.get("screened_out") else " (not chosen)"
    return None, ""


STAGES = ("scan", "screening", "candidate", "multi-start", "cross-validation", "converging", "recheck")


def time_by_stage(path):
    """CPU seconds per stage kind from diagnose.log's "time in STAGE ..." lines,
    the three largest as "multi-start 96, candidate 80, scan 61"."""
    totals = {}
    try:
        lines = open(path).read().splitlines()
    except OSError:
        return ""
    for line in lines:
        line = line.strip()
        if not line.startswith("time in "):
            continue
        name, _, rest = line[len("time in "):].partition("  ")
        words = rest.split()
        try:
            cpu = float(words[words.index("CPU") - 2])
        except (ValueError, IndexError):
            continue
        kind = next((k for k in STAGES if name.startswith(k)), "baseline")
        totals[kind] = totals.get(kind, 0.0) + cpu
    top = sorted(totals.items(), key=lambda kv: -kv[1])[:3]
    return ", ".join("%s %.0f" % kv for kv in top)


def row(work, case):
    base = os.path.join(work, case)
    truth = load(os.path.join(base, "data", "truth.json"))
    summary = load(os.path.join(base, "compare", "summary.json"))
    diag = load(os.path.join(base, "diagnose", "diagnosis.json"))
    if truth is None:
        return None
    truths = true_values(truth)
    effects = ", ".join(sorted(truth.get("effects", {}))) or "none"
    true_text = "<br>".join("%s.%s = %s" % (e, n, g(v)) for e, n, v in truths) or "-"
    rmse = summary["rmse_mm"] if summary else float("nan")
    floor = summary.get("noise_floor_mm", 1.04) if summary else 1.04
    signal = math.sqrt(max(rmse * rmse - floor * floor, 0.0)) if summary else float("nan")
    if diag is None:
        return [case, effects, true_text, "%.3f (%.2f)" % (rmse, signal), "not run", "", "", "", "", "", "", "", ""]
    verdict = ", ".join(diag["verdict"]) or "none"
    expected = expected_verdict(truth)
    correct = sorted(diag["verdict"]) == expected
    hidden = expected and undetectable(summary)
    if hidden:
        correct = correct or (not diag["verdict"] and diag.get("explained") is not False)
    unknown = [e for e in truth.get("effects", {}) if NEAREST.get(e) == []]
    if unknown:
        correct = correct and diag.get("explained") is False
    ranking = []
    for c in diag["ranking"][:3]:
        mark = "*" if c["significant"] else ("s" if c.get("screened_out") else "")
        ranking.append("%s %s%s" % (c["effect"], bic_text(c["delta_bic"]), mark))
    for c in diag.get("later_rounds", []):
        if c["significant"]:
            ranking.append("then %s %s*" % (c["effect"], bic_text(c["delta_bic"])))
    fitted = []
    for e, n, v in truths:
        f, note = fitted_value(diag, e, n)
        fitted.append("%s.%s = %s%s" % (e, n, g(f), note) if f is not None else "%s.%s: -" % (e, n))
    for e in truth.get("effects", {}):
        for nearest in NEAREST.get(e, []):
            for n, f in sorted(diag.get("final_params", {}).get("effects", {}).get(nearest, {}).items()):
                fitted.append("nearest %s.%s = %s" % (nearest, n, g(f)))
    surface = diag["final_params"]["surface"]
    surface_text = "m %.3f, k %.1f, kj %.2f" % (surface["mass_kg"], surface["spring_k"], surface["kappa_jam"])
    ladder = diag["ladder"]
    rmse_text = "%.3f -> %.3f (floor %.3f)" % (ladder[0]["rmse_mm"], ladder[-1]["rmse_mm"], diag["noise_floor_mm"])
    explained = diag.get("explained")
    explained_text = "-" if explained is None else ("yes" if explained else "**no**")
    worst = diag.get("worst_cells") or []
    if worst and explained is False:
        explained_text += " (worst cell [%d, %d])" % tuple(worst[0])
    verdict_text = ("**%s**" if correct else "%s (WRONG)") % verdict
    if hidden:
        verdict_text += " (the effect is within the noise)"
    return [case, effects, true_text, "%.3f (%.2f)" % (rmse, signal), verdict_text, "<br>".join(ranking),
            "<br>".join(fitted) or "-",
            surface_text, rmse_text, explained_text, "%.0f" % diag["seconds"], "%.0f" % diag["cpu_seconds"],
            time_by_stage(os.path.join(base, "diagnose.log"))]


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    work, sessions, cases = sys.argv[1], sys.argv[2], sys.argv[3:]
    head = ["dataset", "true effects", "true parameters", "RMSE vs baseline mm (effect alone)", "verdict",
            "ranking top 3: delta BIC (* significant, s screened out)", "fitted vs true", "final m kg, k N/m, kappa_jam",
            "RMSE mm baseline -> final", "explained", "wall s", "CPU s", "CPU s by stage (top 3)"]
    print("Sessions of demo-baseline replayed: %s." % sessions.replace(",", ", "))
    print()
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for case in cases:
        r = row(work, case)
        if r:
            print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
