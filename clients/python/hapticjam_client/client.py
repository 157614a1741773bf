"""Client: one channel to a hapticjam-server, the bearer token on every call,
and the PlanningService, DeviceService and CalibrationService (compare,
fit, diagnose) calls as methods. A refused call
raises ClientError carrying the gRPC status code and the server's message."""

import json
import os

import grpc
from hapticjam.v1 import (array_pb2, calibration_service_pb2, calibration_service_pb2_grpc, device_service_pb2,
                          device_service_pb2_grpc, goal_pb2, plan_pb2, planning_service_pb2,
                          planning_service_pb2_grpc, render_service_pb2, render_service_pb2_grpc)

# Goals (meshes, DEMs) may exceed gRPC's 4 MiB default; the server takes up to 64 MiB.
MAX_MESSAGE_BYTES = 64 << 20

JOB_STATES = {v: k[len("JOB_STATE_"):].lower() for k, v in device_service_pb2.JobState.items()}
FINISHED = {device_service_pb2.JOB_STATE_DONE, device_service_pb2.JOB_STATE_FAILED,
            device_service_pb2.JOB_STATE_CANCELLED, device_service_pb2.JOB_STATE_INTERRUPTED}


class ClientError(Exception):
    """A call the server (or gRPC) refused: .code is a grpc.StatusCode, .details the message."""

    def __init__(self, call, error):
        self.call = call
        self.code = error.code()
        self.details = error.details()
        super().__init__(f"{call}: {self.code.name}: {self.details}")


def file_goal(path, region=None, max_height_mm=0.0, up_axis="", hue=False, view_resolution=0, absolute=False):
    """A Goal from a file's bytes (the format follows its extension).
    region: (x0, y0, x1, y1), fractions of the image, or pixels if any exceeds 1.
    absolute: a CSV or float TIFF taken as mm above the clamped edge's plane
    (not rescaled; (R p + 1) x (C p + 1) values are the goal at the mesh points)."""
    with open(path, "rb") as f:
        content = f.read()
    goal = goal_pb2.Goal(file=goal_pb2.GoalFile(content=content, file_name=os.path.basename(path)))
    goal = _finish_goal(goal, region, max_height_mm, up_axis, hue, view_resolution)
    if absolute:
        goal.options.heights = goal_pb2.GOAL_HEIGHTS_ABSOLUTE
    return goal


def map_goal(name, region=None, max_height_mm=0.0):
    """A Goal naming a map the server was started with (--map NAME=FILE)."""
    return _finish_goal(goal_pb2.Goal(map_name=name), region, max_height_mm, "", False, 0)


def _finish_goal(goal, region, max_height_mm, up_axis, hue, view_resolution):
    if region is not None:
        x0, y0, x1, y1 = region
        goal.region.CopyFrom(goal_pb2.Region(x0=x0, y0=y0, x1=x1, y1=y1, pixels=any(v > 1 for v in region)))
    goal.options.CopyFrom(goal_pb2.GoalOptions(
        max_height_mm=max_height_mm, up_axis=up_axis, view_resolution=view_resolution,
        encoding=goal_pb2.HEIGHT_ENCODING_HUE if hue else goal_pb2.HEIGHT_ENCODING_UNSPECIFIED))
    return goal


def dataset_upload(path):
    """An UploadedDataset from a dataset folder: each sub-folder holding a
    session.json, with the frame files its steps name (the server validates)."""
    dataset = calibration_service_pb2.UploadedDataset(name=os.path.basename(os.path.abspath(path)))
    for name in sorted(os.listdir(path)):
        folder = os.path.join(path, name)
        session_file = os.path.join(folder, "session.json")
        if not os.path.isfile(session_file):
            continue
        with open(session_file) as f:
            text = f.read()
        session = dataset.sessions.add(name=name, session_json=text)
        try:
            frames = {s["frame"] for s in json.loads(text).get("steps", []) if isinstance(s.get("frame"), str)}
        except (ValueError, AttributeError):
            frames = set()  # the server names what is wrong
        for frame in sorted(frames):
            if os.path.isfile(os.path.join(folder, frame)):
                with open(os.path.join(folder, frame), "rb") as f:
                    session.files.add(path=frame, content=f.read())
    return dataset


def _calibration_options(params_json="", effects=(), segments=0, threads=0, max_iterations=0):
    """CalibrationOptions; 0 and empty mean the commands' defaults."""
    return calibration_service_pb2.CalibrationOptions(params_json=params_json, effects=list(effects),
                                                      segments=segments, threads=threads,
                                                      max_iterations=max_iterations)


def array_spec(rows, cols, segments=0, cell_size_mm=0.0):
    return array_pb2.ArraySpec(rows=rows, cols=cols, segments=segments, cell_size_mm=cell_size_mm)


def plan_from_steps(steps, planner=""):
    """A Plan from session-format steps (the "steps" of a plan.json), e.g.
    [{"op": "set_pressure", "kpa": 0.3}, {"op": "jam", "cell": [0, 1]}, {"op": "capture"}]."""
    plan = plan_pb2.Plan(planner=planner)
    for i, s in enumerate(steps):
        op = s.get("op")
        step = plan.steps.add(label=s.get("label", ""))
        if op == "set_pressure":
            step.set_pressure.kpa = float(s["kpa"])
        elif op in ("jam", "unjam"):
            getattr(step, op).CopyFrom(array_pb2.CellIndex(row=s["cell"][0], col=s["cell"][1]))
        elif op in ("pin", "unpin"):
            getattr(step, op).CopyFrom(array_pb2.NodeIndex(a=s["node"][0], b=s["node"][1]))
        elif op == "capture":
            step.capture.SetInParent()
        else:
            raise ValueError(f"step {i}: unknown op {op!r}")
    return plan


def plan_from_file(path):
    """The Plan in a plan.json (what `hapticjam plan` writes) or a session.json."""
    with open(path) as f:
        doc = json.load(f)
    return plan_from_steps(doc["steps"] if isinstance(doc, dict) else doc,
                           doc.get("planner", "") if isinstance(doc, dict) else "")


class Client:
    """client = Client("127.0.0.1:50051", token="..."); client.preview(...)."""

    def __init__(self, server, token=None, root_certificates=None):
        options = [("grpc.max_receive_message_length", MAX_MESSAGE_BYTES),
                   ("grpc.max_send_message_length", MAX_MESSAGE_BYTES)]
        if root_certificates is None:
            self.channel = grpc.insecure_channel(server, options=options)
        else:
            self.channel = grpc.secure_channel(server, grpc.ssl_channel_credentials(root_certificates), options)
        self.server = server
        self.metadata = [("authorization", "Bearer " + token)] if token else []
        self.planning = planning_service_pb2_grpc.PlanningServiceStub(self.channel)
        self.device = device_service_pb2_grpc.DeviceServiceStub(self.channel)
        self.calibration = calibration_service_pb2_grpc.CalibrationServiceStub(self.channel)
        self.rendering = render_service_pb2_grpc.RenderServiceStub(self.channel)

    def close(self):
        self.channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _call(self, name, method, request, timeout):
        try:
            return method(request, timeout=timeout, metadata=self.metadata)
        except grpc.RpcError as e:
            raise ClientError(name, e) from None

    # -- planning --

    def planners(self, timeout=30):
        return self._call("ListPlanners", self.planning.ListPlanners, planning_service_pb2.ListPlannersRequest(),
                          timeout)

    def preview(self, goal, rows, cols, segments=0, planner="", timeout=120):
        request = planning_service_pb2.PreviewRequest(array=array_spec(rows, cols, segments), goal=goal,
                                                      planner=planner)
        return self._call("Preview", self.planning.Preview, request, timeout)

    def plan(self, goal, rows, cols, segments=0, planner="", on_event=None, omit_snapshots=False, timeout=None):
        """Streams a plan; on_event(PlanEvent) sees every progress and snapshot.
        Returns (PlanResult, number of snapshots)."""
        request = planning_service_pb2.PlanRequest(array=array_spec(rows, cols, segments), goal=goal,
                                                   planner=planner, omit_snapshots=omit_snapshots)
        result, snapshots = None, 0
        try:
            for event in self.planning.Plan(request, timeout=timeout, metadata=self.metadata):
                if on_event:
                    on_event(event)
                kind = event.WhichOneof("event")
                if kind == "snapshot":
                    snapshots += 1
                elif kind == "result":
                    result = event.result
        except grpc.RpcError as e:
            raise ClientError("Plan", e) from None
        if result is None:
            raise RuntimeError("the server ended the plan stream without a result")
        return result, snapshots

    # -- rendering --

    def render(self, goal, rows, cols, segments=0, planner="", iterations=0, correction="both", gain=0.0,
               name="", on_event=None, timeout=None):
        """Renders `goal` on the server's device with the loop closed (docs/render.md):
        plan, run, capture, compare with the goal, correct the targets, again.
        on_event(RenderEvent) sees every progress and iteration event.
        correction: "both" (the default: the model, then the targets), "targets" (learn the
        targets from the error), "model" (probe the device after the first run, fit its model
        on the probe and plan with it), or "none" (open loop).
        Returns (RenderResult, [RenderIteration, ...])."""
        corrections = {"targets": render_service_pb2.RENDER_CORRECTION_TARGETS,
                       "model": render_service_pb2.RENDER_CORRECTION_MODEL,
                       "both": render_service_pb2.RENDER_CORRECTION_BOTH,
                       "none": render_service_pb2.RENDER_CORRECTION_NONE}
        if correction not in corrections:
            raise ValueError(f"correction must be one of {sorted(corrections)}, got {correction!r}")
        request = render_service_pb2.RenderRequest(array=array_spec(rows, cols, segments), goal=goal, planner=planner,
                                                   iterations=iterations, correction=corrections[correction],
                                                   gain=gain, name=name)
        result, iterations_seen = None, []
        try:
            for event in self.rendering.Render(request, timeout=timeout, metadata=self.metadata):
                if on_event:
                    on_event(event)
                kind = event.WhichOneof("event")
                if kind == "iteration":
                    iterations_seen.append(event.iteration)
                elif kind == "result":
                    result = event.result
        except grpc.RpcError as e:
            raise ClientError("Render", e) from None
        if result is None:
            raise RuntimeError("the server ended the render stream without a result")
        return result, iterations_seen

    # -- calibration --

    def compare(self, dataset, params_json="", effects=(), segments=0, threads=0, scale_mm=0.0, on_progress=None,
                timeout=None):
        """Compares the model with an UploadedDataset (dataset_upload(path));
        on_progress(CalibrationProgress) sees every progress event. Returns the
        CompareResult (summary_json, rmse_mm, mae_mm, samples, noise_floor_mm,
        report_html: a self-contained page, maps: the heat-map PNGs by path;
        scale_mm: their colour scale, 0 = 5 mm)."""
        options = _calibration_options(params_json, effects, segments, threads)
        options.scale_mm = scale_mm
        request = calibration_service_pb2.CompareRequest(dataset=dataset, options=options)
        return self._calibration_stream("Compare", self.calibration.Compare, request, on_progress, timeout)

    def fit(self, dataset, params_json="", effects=(), segments=0, threads=0, max_iterations=0, holdout=(),
            no_initial=False, profile=(), on_progress=None, timeout=None):
        """Fits the model (and `effects`) to an UploadedDataset, as `hapticjam
        fit` does; `holdout` names sessions left out and reported as held out.
        Returns the FitResult (params_json, rmse_mm, r2, heldout_rmse_mm,
        parameters with their 95 % intervals, noise_floor_mm, report_html)."""
        request = calibration_service_pb2.FitRequest(
            dataset=dataset, options=_calibration_options(params_json, effects, segments, threads, max_iterations),
            holdout=list(holdout), no_initial=no_initial, profile=list(profile))
        return self._calibration_stream("Fit", self.calibration.Fit, request, on_progress, timeout)

    def diagnose(self, dataset, params_json="", effects=(), segments=0, threads=0, max_iterations=0,
                 no_screening=False, on_progress=None, timeout=None):
        """Finds the effects the data need, as `hapticjam diagnose` does
        (`effects`: the candidates; none = all). Returns the DiagnoseResult
        (diagnosis_json, params_json, verdict, baseline and final RMSE,
        report_html: the page with the error ladder)."""
        request = calibration_service_pb2.DiagnoseRequest(
            dataset=dataset, options=_calibration_options(params_json, effects, segments, threads, max_iterations),
            no_screening=no_screening)
        return self._calibration_stream("Diagnose", self.calibration.Diagnose, request, on_progress, timeout)

    def _calibration_stream(self, name, method, request, on_progress, timeout):
        """Reads a calibration call's stream: progress events to on_progress,
        then its one result."""
        result = None
        try:
            for event in method(request, timeout=timeout, metadata=self.metadata):
                if event.WhichOneof("event") == "progress":
                    if on_progress:
                        on_progress(event.progress)
                else:
                    result = event.result
        except grpc.RpcError as e:
            raise ClientError(name, e) from None
        if result is None:
            raise RuntimeError(f"the server ended the {name} stream without a result")
        return result

    # -- device --

    def submit(self, plan, name="", timeout=30):
        request = device_service_pb2.SubmitJobRequest(plan=plan, name=name)
        return self._call("SubmitJob", self.device.SubmitJob, request, timeout).job

    def cancel(self, job_id, timeout=30):
        return self._call("CancelJob", self.device.CancelJob, device_service_pb2.CancelJobRequest(id=job_id),
                          timeout).job

    def job(self, job_id, timeout=30):
        return self._call("GetJob", self.device.GetJob, device_service_pb2.GetJobRequest(id=job_id), timeout)

    def status(self, timeout=30):
        return self._call("GetDeviceStatus", self.device.GetDeviceStatus,
                          device_service_pb2.GetDeviceStatusRequest(), timeout)

    def stop(self, reason="", timeout=30):
        return self._call("EmergencyStop", self.device.EmergencyStop,
                          device_service_pb2.EmergencyStopRequest(reason=reason), timeout)

    def resume(self, timeout=30):
        return self._call("ResumeQueue", self.device.ResumeQueue, device_service_pb2.ResumeQueueRequest(), timeout)

    def watch(self, recent_finished=0, timeout=None):
        """Yields QueueState now and at every change (a generator; cancel by leaving it)."""
        stream = self.device.WatchQueue(device_service_pb2.WatchQueueRequest(recent_finished=recent_finished),
                                        timeout=timeout, metadata=self.metadata)
        try:
            yield from stream
        except grpc.RpcError as e:
            if e.code() != grpc.StatusCode.CANCELLED:
                raise ClientError("WatchQueue", e) from None
        finally:
            stream.cancel()

    def wait_for_job(self, job_id, timeout=60):
        """Follows the queue until job_id has finished; returns that Job (with its captures)."""
        for state in self.watch(recent_finished=32, timeout=timeout):
            for j in state.jobs:
                if j.id == job_id and j.state in FINISHED:
                    return self.job(job_id)
        raise RuntimeError(f"the queue stream ended before job {job_id} finished")
