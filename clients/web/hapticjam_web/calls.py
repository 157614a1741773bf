"""The gateway's side of the API: one gRPC channel to the server, and each
page request as the gRPC call it stands for, made with the caller's own
bearer token (the gateway has none). A refused call raises CallError with
the server's status code and message."""

import os

import grpc
from hapticjam.v1 import (calibration_service_pb2, calibration_service_pb2_grpc, device_service_pb2,
                          device_service_pb2_grpc, planning_service_pb2, planning_service_pb2_grpc)
from hapticjam_client.client import MAX_MESSAGE_BYTES, array_spec, dataset_upload

from . import convert


class CallError(Exception):
    """A gRPC call that failed: .call, .code (grpc.StatusCode) and .details."""

    def __init__(self, call, error):
        self.call, self.code, self.details = call, error.code(), error.details()
        super().__init__(f"{call}: {self.code.name}: {self.details}")


class Gateway:
    """Stubs on one channel, the maps the gateway can draw and the datasets it may upload."""

    def __init__(self, server, maps=None, datasets=None):
        options = [("grpc.max_receive_message_length", MAX_MESSAGE_BYTES),
                   ("grpc.max_send_message_length", MAX_MESSAGE_BYTES)]
        self.server = server
        self.channel = grpc.insecure_channel(server, options=options)
        self.planning = planning_service_pb2_grpc.PlanningServiceStub(self.channel)
        self.device = device_service_pb2_grpc.DeviceServiceStub(self.channel)
        self.calibration = calibration_service_pb2_grpc.CalibrationServiceStub(self.channel)
        self.maps = dict(maps or {})          # NAME -> goal file the browser may draw
        self.datasets = dict(datasets or {})  # NAME -> dataset folder

    def close(self):
        self.channel.close()

    @staticmethod
    def metadata(token):
        return [("authorization", "Bearer " + token)] if token else []

    def unary(self, name, method, request, token, timeout=120):
        try:
            return method(request, timeout=timeout, metadata=self.metadata(token))
        except grpc.RpcError as e:
            raise CallError(name, e) from None

    # -- planning --

    def info(self, token):
        r = self.unary("ListPlanners", self.planning.ListPlanners, planning_service_pb2.ListPlannersRequest(), token, 30)
        return {"server": self.server, "planners": list(r.planners), "maps": list(r.maps),
                "goal_extensions": list(r.goal_extensions),
                "map_files": {name: os.path.basename(path) for name, path in self.maps.items()},
                "datasets": sorted(self.datasets)}

    def plan_stream(self, body, token):
        """The streaming call of a PlanRequest, and how to turn its events into JSON."""
        rows, cols, segments = convert.array_from_json(body)
        request = planning_service_pb2.PlanRequest(array=array_spec(rows, cols, segments),
                                                   goal=convert.goal_from_json(convert.need(body, "goal", dict, "request")),
                                                   planner=convert.optional(body, "planner", str, "", "request"))
        return self.planning.Plan(request, metadata=self.metadata(token)), convert.plan_event_json

    def preview(self, body, token):
        rows, cols, segments = convert.array_from_json(body)
        request = planning_service_pb2.PreviewRequest(array=array_spec(rows, cols, segments),
                                                      goal=convert.goal_from_json(convert.need(body, "goal", dict, "request")),
                                                      planner=convert.optional(body, "planner", str, "", "request"))
        return convert.preview_json(self.unary("Preview", self.planning.Preview, request, token, 600))

    # -- device --

    def role(self, token):
        """What the caller may do, learnt without changing anything: CancelJob
        of job 0 (no such job) is refused for a preview caller before the
        lookup (PERMISSION_DENIED) and NOT_FOUND for an operator or admin. The
        API has no call that tells an operator from an admin."""
        probe = device_service_pb2.CancelJobRequest(id=0)
        try:
            self.device.CancelJob(probe, timeout=30, metadata=[])
            return {"role": "admin", "auth": False}
        except grpc.RpcError as e:
            if e.code() == grpc.StatusCode.NOT_FOUND:  # a server without --auth: every caller is "local", admin
                return {"role": "admin", "auth": False}
            if e.code() != grpc.StatusCode.UNAUTHENTICATED:
                raise CallError("CancelJob", e) from None
        if not token:
            return {"role": "none", "auth": True}
        try:
            self.device.CancelJob(probe, timeout=30, metadata=self.metadata(token))
        except grpc.RpcError as e:
            if e.code() == grpc.StatusCode.PERMISSION_DENIED:
                return {"role": "preview", "auth": True}
            if e.code() == grpc.StatusCode.NOT_FOUND:
                return {"role": "operator", "auth": True}
            raise CallError("CancelJob", e) from None
        return {"role": "operator", "auth": True}

    def watch_stream(self, recent, token):
        request = device_service_pb2.WatchQueueRequest(recent_finished=recent)
        return self.device.WatchQueue(request, metadata=self.metadata(token)), convert.queue_json

    def status(self, token):
        return convert.status_json(self.unary("GetDeviceStatus", self.device.GetDeviceStatus,
                                              device_service_pb2.GetDeviceStatusRequest(), token, 30))

    def submit(self, body, token):
        request = device_service_pb2.SubmitJobRequest(plan=convert.plan_from_json(body),
                                                      name=convert.optional(body, "name", str, "", "request"))
        return convert.job_json(self.unary("SubmitJob", self.device.SubmitJob, request, token, 30).job)

    def cancel(self, body, token):
        request = device_service_pb2.CancelJobRequest(id=convert.need(body, "id", int, "request"))
        return convert.job_json(self.unary("CancelJob", self.device.CancelJob, request, token, 30).job)

    def stop(self, body, token):
        request = device_service_pb2.EmergencyStopRequest(reason=convert.optional(body, "reason", str, "", "request"))
        return convert.status_json(self.unary("EmergencyStop", self.device.EmergencyStop, request, token, 30))

    def resume(self, token):
        return convert.queue_json(self.unary("ResumeQueue", self.device.ResumeQueue,
                                             device_service_pb2.ResumeQueueRequest(), token, 30))

    # -- calibration --

    def calibration_stream(self, kind, body, token):
        """Compare, Fit or Diagnose of a dataset the gateway was given
        ({"dataset": NAME}) or one the browser uploaded ({"upload": {...}})."""
        if "upload" in body:
            dataset = convert.dataset_from_json(convert.need(body, "upload", dict, "request"))
        else:
            name = convert.need(body, "dataset", str, "request")
            if name not in self.datasets:
                raise convert.BadRequest(f"request.dataset \"{name}\" is not a dataset of this gateway "
                                         f"(known: {', '.join(sorted(self.datasets)) or 'none'})")
            dataset = dataset_upload(self.datasets[name])
        options = convert.calibration_options_from_json(convert.optional(body, "options", dict, {}, "request"))
        if kind == "compare":
            request, method = calibration_service_pb2.CompareRequest(dataset=dataset, options=options), \
                self.calibration.Compare
        elif kind == "fit":
            request, method = calibration_service_pb2.FitRequest(dataset=dataset, options=options), self.calibration.Fit
        else:
            request, method = calibration_service_pb2.DiagnoseRequest(dataset=dataset, options=options), \
                self.calibration.Diagnose

        def event_json(event):
            if event.WhichOneof("event") == "progress":
                return {"progress": convert.progress_json(event.progress)}
            return {"result": convert.calibration_result_json(kind, event.result)}

        return method(request, metadata=self.metadata(token)), event_json
