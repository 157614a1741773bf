"""JSON from the browser to the API's messages, and the API's messages back
to JSON the pages draw. Field names follow proto/ where they can."""

import base64
import json

from hapticjam.v1 import calibration_service_pb2, goal_pb2
from hapticjam_client.client import JOB_STATES, _calibration_options, plan_from_steps


class BadRequest(ValueError):
    """A request body the gateway cannot turn into a call; the message names the field."""


def need(doc, key, kind, where):
    """doc[key] checked to be of `kind`, else BadRequest naming `where.key`."""
    if not isinstance(doc, dict) or key not in doc:
        raise BadRequest(f"{where}.{key} is missing")
    value = doc[key]
    if kind is int and isinstance(value, bool) or not isinstance(value, kind):
        names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
        raise BadRequest(f"{where}.{key} must be {names}, got {json.dumps(value)[:40]}")
    return value


def optional(doc, key, kind, default, where):
    return need(doc, key, kind, where) if key in doc and doc[key] is not None else default


def decode_b64(text, where):
    try:
        return base64.b64decode(text, validate=True)
    except (ValueError, TypeError):
        raise BadRequest(f"{where} is not base64") from None


def goal_from_json(doc):
    """{"map": NAME} or {"file": {"name", "content_b64", "sidecar_json"?}}, with
    "region": [x0, y0, x1, y1] (fractions), "max_height_mm", "up_axis", "hue"."""
    if not isinstance(doc, dict):
        raise BadRequest("goal must be an object")
    goal = goal_pb2.Goal()
    if "map" in doc:
        goal.map_name = need(doc, "map", str, "goal")
    elif "file" in doc:
        f = need(doc, "file", dict, "goal")
        goal.file.file_name = need(f, "name", str, "goal.file")
        goal.file.content = decode_b64(need(f, "content_b64", str, "goal.file"), "goal.file.content_b64")
        goal.file.sidecar_json = optional(f, "sidecar_json", str, "", "goal.file").encode()
    else:
        raise BadRequest("goal needs \"map\" or \"file\"")
    region = optional(doc, "region", list, None, "goal")
    if region is not None:
        if len(region) != 4 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in region):
            raise BadRequest("goal.region must be four numbers [x0, y0, x1, y1]")
        goal.region.CopyFrom(goal_pb2.Region(x0=region[0], y0=region[1], x1=region[2], y1=region[3]))
    goal.options.SetInParent()  # as the CLI sends it, so that equal requests share a cache entry
    goal.options.max_height_mm = float(optional(doc, "max_height_mm", (int, float), 0, "goal"))
    goal.options.up_axis = optional(doc, "up_axis", str, "", "goal")
    if optional(doc, "hue", bool, False, "goal"):
        goal.options.encoding = goal_pb2.HEIGHT_ENCODING_HUE
    return goal


def array_from_json(doc):
    """(rows, cols, segments) of a plan or preview request."""
    return (need(doc, "rows", int, "request"), need(doc, "cols", int, "request"),
            optional(doc, "segments", int, 0, "request"))


def plan_from_json(doc):
    """The Plan of {"steps": [session-format steps], "planner": NAME}."""
    steps = need(doc, "steps", list, "request")
    try:
        return plan_from_steps(steps, optional(doc, "planner", str, "", "request"))
    except (KeyError, TypeError, IndexError, ValueError, AttributeError) as e:
        raise BadRequest(f"request.steps: {e}") from None


def dataset_from_json(doc):
    """An UploadedDataset from {"name", "sessions": [{"name", "session_json", "files": [{"path", "content_b64"}]}]}."""
    dataset = calibration_service_pb2.UploadedDataset(name=need(doc, "name", str, "dataset"))
    for i, s in enumerate(need(doc, "sessions", list, "dataset")):
        where = f"dataset.sessions[{i}]"
        session = dataset.sessions.add(name=need(s, "name", str, where), session_json=need(s, "session_json", str, where))
        for k, f in enumerate(optional(s, "files", list, [], where)):
            fw = f"{where}.files[{k}]"
            session.files.add(path=need(f, "path", str, fw), content=decode_b64(need(f, "content_b64", str, fw), fw))
    return dataset


def calibration_options_from_json(doc):
    effects = optional(doc, "effects", list, [], "options")
    if not all(isinstance(e, str) for e in effects):
        raise BadRequest("options.effects must be a list of effect names")
    options = _calibration_options(
        params_json=optional(doc, "params_json", str, "", "options"),
        effects=effects,
        segments=optional(doc, "segments", int, 0, "options"),
        max_iterations=optional(doc, "max_iterations", int, 0, "options"))
    return options


# -- API messages to JSON --

def snapshot_json(s):
    return {"point_rows": s.point_rows, "point_cols": s.point_cols, "heights_mm": list(s.heights_mm),
            "x_mm": list(s.x_mm), "y_mm": list(s.y_mm), "pressure_pa": s.pressure_pa,
            "jammed_cells": [[c.row, c.col] for c in s.jammed_cells],
            "pinned_nodes": [[n.a, n.b] for n in s.pinned_nodes], "steps_applied": s.steps_applied}


def correlation_json(message):
    return message.correlation if message.HasField("correlation") else None


def plan_result_json(r):
    return {"steps": json.loads(r.steps_json or "[]"), "planner": r.plan.planner, "predicted": snapshot_json(r.predicted),
            "goal_heights_mm": list(r.goal_heights_mm), "correlation": correlation_json(r),
            "correlation_undefined": r.correlation_undefined, "laplace_mean": r.laplace_mean, "cached": r.cached,
            "seconds": r.seconds}


def preview_json(r):
    return {"predicted": snapshot_json(r.predicted), "goal_heights_mm": list(r.goal_heights_mm),
            "correlation": correlation_json(r), "correlation_undefined": r.correlation_undefined,
            "laplace_mean": r.laplace_mean, "step_count": r.step_count, "cached": r.cached, "seconds": r.seconds}


def plan_event_json(event):
    kind = event.WhichOneof("event")
    if kind == "progress":
        return {"progress": {"fraction": event.progress.fraction, "message": event.progress.message}}
    if kind == "snapshot":
        return {"snapshot": snapshot_json(event.snapshot)}
    return {"result": plan_result_json(event.result)}


def job_json(j):
    return {"id": j.id, "owner": j.owner, "name": j.name, "state": JOB_STATES.get(j.state, str(j.state)),
            "position": j.position, "steps_done": j.steps_done, "steps_total": j.steps_total, "error": j.error,
            "submitted_unix_ms": j.submitted_unix_ms, "finished_unix_ms": j.finished_unix_ms,
            "captures": len(j.captures)}


def queue_json(q):
    return {"jobs": [job_json(j) for j in q.jobs], "paused": q.paused, "pause_reason": q.pause_reason,
            "device_connected": q.device_connected}


def status_json(s):
    return {"connected": s.connected, "endpoint": s.endpoint, "rows": s.rows, "cols": s.cols,
            "pressure_pa": s.pressure_pa, "max_pressure_pa": s.max_pressure_pa,
            "jammed_cells": [[c.row, c.col] for c in s.jammed_cells],
            "pinned_nodes": [[n.a, n.b] for n in s.pinned_nodes], "last_error": s.last_error,
            "queue_paused": s.queue_paused, "pause_reason": s.pause_reason, "emergency_stopped": s.emergency_stopped}


def progress_json(p):
    out = {"stage": p.stage, "done": p.done, "total": p.total, "detail": p.detail}
    if p.HasField("rmse_mm"):
        out["rmse_mm"] = p.rmse_mm
    return out


def calibration_result_json(kind, r):
    """The key figures of a Compare, Fit or Diagnose result and its report page."""
    out = {"kind": kind, "report_html": r.report_html, "noise_floor_mm": r.noise_floor_mm, "seconds": r.seconds}
    if kind == "compare":
        out.update(rmse_mm=r.rmse_mm, mae_mm=r.mae_mm, samples=r.samples)
    elif kind == "fit":
        out.update(rmse_mm=r.rmse_mm, r2=r.r2, params_json=r.params_json,
                   heldout_rmse_mm=r.heldout_rmse_mm if r.HasField("heldout_rmse_mm") else None,
                   parameters=[{"name": p.name, "value": p.value, "unit": p.unit, "active": p.active,
                                "ci95_low": p.ci95_low, "ci95_high": p.ci95_high} for p in r.parameters])
    else:
        out.update(verdict=list(r.verdict), baseline_rmse_mm=r.baseline_rmse_mm, final_rmse_mm=r.final_rmse_mm,
                   final_heldout_rmse_mm=r.final_heldout_rmse_mm, params_json=r.params_json)
    return out
