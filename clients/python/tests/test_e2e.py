"""End to end with the Python client: the real hapticjam-server and
hapticjam-device-emulator on loopback ports, driven through hapticjam_client
(and the examples, and the C++ CLI as a second client). Run by ctest
(python_client_e2e) with PYTHONPATH, HJ_SERVER_PATH, HJ_EMULATOR_PATH,
HJ_SHARED_DIR and HJ_CLI_PATH set."""

import json
import os
import re
import socket
import struct
import subprocess
import sys
import tempfile
import time
import unittest

import grpc
from hapticjam_client import Client, ClientError, dataset_upload, file_goal
from hapticjam_client.client import plan_from_steps
from hapticjam.v1 import array_pb2, planning_service_pb2

SERVER = os.environ["HJ_SERVER_PATH"]
EMULATOR = os.environ["HJ_EMULATOR_PATH"]
CLI = os.environ["HJ_CLI_PATH"]
SHARED = os.environ["HJ_SHARED_DIR"]
DEM = os.path.join(SHARED, "data", "dem", "volcano_maunga_whau.csv")
MESH = os.path.join(SHARED, "data", "mesh", "openscad_letterblock.stl")
DEMO_BASELINE = os.path.join(SHARED, "data", "sessions", "demo-baseline")  # README: M 0.52 kg, k 58 N/m
# Hang bounds (not timing assertions) grow by HJ_TEST_TIME_SCALE: the
# sanitizer build (scripts/sanitize.sh) runs several times slower.
TIME_SCALE = float(os.environ.get("HJ_TEST_TIME_SCALE", "1"))
EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples")


def start(argv, folder, name, pattern):
    """Starts a program printing its port; returns (process, port)."""
    out_path, err_path = os.path.join(folder, name + ".out"), os.path.join(folder, name + ".err")
    with open(out_path, "w") as out, open(err_path, "w") as err:
        process = subprocess.Popen(argv, stdout=out, stderr=err)
    deadline = time.monotonic() + 30 * TIME_SCALE
    while time.monotonic() < deadline:
        with open(out_path) as out:
            m = re.search(pattern, out.read())
        if m:
            return process, int(m.group(1))
        if process.poll() is not None:
            break
        time.sleep(0.02)
    process.kill()
    with open(err_path) as err:
        raise RuntimeError(f"{name} did not start: " + err.read())


def wait_until(predicate, seconds=30):
    """Polls (a bound against hanging, not a timing assertion)."""
    deadline = time.monotonic() + seconds * TIME_SCALE
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return predicate()


class Rig:
    """An emulator and a server on loopback, stopped by close()."""

    def __init__(self, server_flags=(), emulator_flags=()):
        self.folder = tempfile.mkdtemp(prefix="hj_py_e2e_")
        self.emulator, self.emulator_port = start(
            [EMULATOR, "--listen", "127.0.0.1:0", *emulator_flags], self.folder, "emulator",
            r"listening on 127\.0\.0\.1:(\d+)")
        self.server, port = start(
            [SERVER, "--listen", "127.0.0.1:0", "--db", os.path.join(self.folder, "queue.db"),
             "--device", f"127.0.0.1:{self.emulator_port}", *server_flags],
            self.folder, "server", r"listening on port (\d+)")
        self.address = f"127.0.0.1:{port}"

    def close(self):
        for p in (self.server, self.emulator):
            p.kill()
            p.wait()

    def stall_device(self, ms):
        with socket.create_connection(("127.0.0.1", self.emulator_port), timeout=30 * TIME_SCALE) as s:
            s.sendall(f"1 fault stall {ms}\n".encode())
            self.assert_reply(s.recv(256), b"ok 1")

    @staticmethod
    def assert_reply(reply, prefix):
        if not reply.startswith(prefix):
            raise AssertionError(f"emulator said {reply!r}")

    def ready(self, client):
        """Connected and vented: a tiny job has run."""
        assert wait_until(lambda: client.status().connected)
        job = client.submit(plan_from_steps([{"op": "set_pressure", "kpa": 0}]), "warm-up")
        client.wait_for_job(job.id)

    def cli(self, *args, token=None):
        argv = [CLI, "remote", *args, "--server", self.address] + (["--token", token] if token else [])
        return subprocess.run(argv, capture_output=True, text=True, timeout=120 * TIME_SCALE)


def read_varint(data, at):
    value, shift = 0, 0
    while True:
        byte = data[at]
        at += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, at


def length_delimited_fields(data, wanted):
    """The payloads of field `wanted` (wire type 2) in a protobuf message."""
    out, at = [], 0
    while at < len(data):
        key, at = read_varint(data, at)
        field, wire = key >> 3, key & 7
        if wire == 0:
            _, at = read_varint(data, at)
        elif wire == 2:
            size, at = read_varint(data, at)
            if field == wanted:
                out.append(data[at:at + size])
            at += size
        elif wire == 1:
            at += 8
        elif wire == 5:
            at += 4
        else:
            raise ValueError(f"wire type {wire}")
    return out


def reflected_services(address):
    """Service names from gRPC server reflection, as a generic client without
    our .proto files sees them: ServerReflectionRequest{list_services: "*"}
    (field 7), answered by list_services_response (field 6) of ServiceResponse
    names (field 1 of each field-1 entry)."""
    with grpc.insecure_channel(address) as channel:
        info = channel.stream_stream("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo")
        request = bytes([(7 << 3) | 2, 1]) + b"*"
        responses = list(info(iter([request]), timeout=30 * TIME_SCALE))
    names = []
    for response in responses:
        for listing in length_delimited_fields(response, 6):
            for service in length_delimited_fields(listing, 1):
                names += [n.decode() for n in length_delimited_fields(service, 1)]
    return names


def queue_ids(client):
    return [j.id for j in next(client.watch(timeout=30 * TIME_SCALE)).jobs]


class PlanningTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # One worker and one waiting place.
        cls.rig = Rig(["--workers", "1", "--queue-size", "1", "--map", f"volcano={DEM}"])
        cls.client = Client(cls.rig.address)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.rig.close()

    def test_reflection_lists_the_services_for_generic_clients(self):
        names = reflected_services(self.rig.address)
        for service in ("hapticjam.v1.PlanningService", "hapticjam.v1.DeviceService", "grpc.health.v1.Health"):
            self.assertIn(service, names)
        # And it hands out the descriptors: file_containing_symbol (field 4)
        # answered by file_descriptor_response (field 4) holding serialized
        # FileDescriptorProtos (field 1) that name our proto file.
        with grpc.insecure_channel(self.rig.address) as channel:
            info = channel.stream_stream("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo")
            symbol = b"hapticjam.v1.PlanningService"
            request = bytes([(4 << 3) | 2, len(symbol)]) + symbol
            responses = list(info(iter([request]), timeout=30 * TIME_SCALE))
        files = [f for r in responses for d in length_delimited_fields(r, 4) for f in length_delimited_fields(d, 1)]
        file_names = [n.decode() for f in files for n in length_delimited_fields(f, 1)]
        self.assertIn("hapticjam/v1/planning_service.proto", file_names)

    def test_plan_streams_progress_and_snapshots_then_the_result(self):
        fractions, snapshots = [], []

        def seen(event):
            kind = event.WhichOneof("event")
            if kind == "progress":
                fractions.append(event.progress.fraction)
            elif kind == "snapshot":
                snapshots.append(event.snapshot)

        result, count = self.client.plan(file_goal(DEM), 3, 4, on_event=seen, timeout=120 * TIME_SCALE)
        self.assertEqual(count, len(snapshots))
        self.assertGreater(count, 1)
        self.assertEqual(fractions, sorted(fractions))
        self.assertTrue(all(0.0 <= f <= 1.0 for f in fractions))
        # Each snapshot is the 3 x 4 array's 13 x 17 mesh points; their pressures rise as the planner steps up.
        self.assertTrue(all(s.point_rows == 13 and s.point_cols == 17 and len(s.heights_mm) == 221 for s in snapshots))
        self.assertGreater(snapshots[-1].pressure_pa, snapshots[0].pressure_pa)
        self.assertEqual(len(json.loads(result.steps_json)), len(result.plan.steps))
        self.assertTrue(result.HasField("correlation"))
        self.assertGreater(result.correlation, 0.5)

    def test_deadline_then_the_next_request_is_served(self):
        with self.assertRaises(ClientError) as refused:
            self.client.plan(file_goal(DEM), 6, 8, segments=6, timeout=0.5)
        # Known server issue (server/planning_service.cc, plan_or_cached): when the deadline passes
        # first on the server it answers CANCELLED, not DEADLINE_EXCEEDED. Either way the call ends.
        self.assertIn(refused.exception.code, (grpc.StatusCode.DEADLINE_EXCEEDED, grpc.StatusCode.CANCELLED))
        # The only worker is free again (bounded wait: it stops within a fraction of a second).
        self.assertTrue(wait_until(lambda: self._preview_ok((0.0, 0.0, 0.6, 0.6))))

    def test_a_full_planning_queue_refuses_at_once_and_cancel_frees_it(self):
        def long_plan(k):
            region = (0.0, 0.0, 1.0 - 0.01 * k, 1.0)  # distinct, so neither is a cache hit
            request = planning_service_pb2.PlanRequest(array=array_pb2.ArraySpec(rows=6, cols=8, segments=6),
                                                       goal=file_goal(DEM, region=region))
            return self.client.planning.Plan(request, timeout=120 * TIME_SCALE)

        running = long_plan(1)
        next(running)  # it holds the one worker
        waiting = long_plan(2)  # it takes the one waiting place
        self.assertTrue(wait_until(lambda: self._refused_at_once()))
        with self.assertRaises(ClientError) as refused:
            self.client.preview(file_goal(DEM), 3, 4)
        self.assertEqual(refused.exception.code, grpc.StatusCode.RESOURCE_EXHAUSTED)
        self.assertIn("queue", refused.exception.details)
        running.cancel()
        waiting.cancel()
        self.assertTrue(wait_until(lambda: self._preview_ok((0.1, 0.1, 0.9, 0.9))))

    def _refused_at_once(self):
        """True once a preview is refused (the second plan has reached the waiting place)."""
        try:
            self.client.preview(file_goal(DEM, region=(0.0, 0.0, 0.5, 0.5)), 3, 4, timeout=0.5)
        except ClientError as e:
            return e.code == grpc.StatusCode.RESOURCE_EXHAUSTED
        return False

    def test_malformed_goal_and_array_are_invalid_arguments(self):
        bad = os.path.join(self.rig.folder, "broken.csv")
        with open(bad, "w") as f:
            f.write("1,2,3\n4,oops,6\n")
        with self.assertRaises(ClientError) as e:
            self.client.preview(file_goal(bad), 3, 4)
        self.assertEqual(e.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("oops", e.exception.details)
        with self.assertRaises(ClientError) as e:
            self.client.preview(file_goal(DEM), 0, 4)
        self.assertEqual(e.exception.code, grpc.StatusCode.INVALID_ARGUMENT)

    def test_map_zoom_example_repeats_come_from_the_cache(self):
        out = subprocess.run([sys.executable, os.path.join(EXAMPLES, "map_zoom.py"), "--server", self.rig.address,
                              "--map", "volcano"], capture_output=True, text=True, timeout=300 * TIME_SCALE)
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = [line.split() for line in out.stdout.splitlines()[1:]]
        self.assertEqual(len(rows), 6)
        self.assertEqual([r[-1] for r in rows], ["no", "no", "no", "no", "yes", "yes"])
        # A repeated region has the same correlation as its first answer.
        self.assertEqual(rows[4][1], rows[2][1])
        self.assertEqual(rows[5][1], rows[0][1])

    def test_cad_preview_example_writes_a_png_of_the_surface(self):
        png = os.path.join(self.rig.folder, "block.png")
        out = subprocess.run([sys.executable, os.path.join(EXAMPLES, "cad_preview.py"), "--server", self.rig.address,
                              MESH, "--out", png], capture_output=True, text=True, timeout=300 * TIME_SCALE)
        self.assertEqual(out.returncode, 0, out.stderr)
        with open(png, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n")
        width, height = struct.unpack(">II", data[16:24])
        # A coarse preview of 3 x 4 cells: 2 segments per cell, 9 x 7 points, 8 px each.
        self.assertEqual((width, height), (9 * 8, 7 * 8))

    def _preview_ok(self, region):
        try:
            self.client.preview(file_goal(DEM, region=region), 3, 4, timeout=60 * TIME_SCALE)
            return True
        except ClientError as e:
            if e.code != grpc.StatusCode.RESOURCE_EXHAUSTED:
                raise
            return False


class DeviceTest(unittest.TestCase):
    def setUp(self):
        self.auth = tempfile.NamedTemporaryFile("w", suffix=".auth", delete=False)
        self.auth.write("alice operator token-alice\nbob operator token-bob\nviewer preview token-view\n")
        self.auth.close()
        self.rig = Rig(["--auth", self.auth.name])
        self.alice = Client(self.rig.address, token="token-alice")

    def tearDown(self):
        self.alice.close()
        self.rig.close()
        os.unlink(self.auth.name)

    def test_two_clients_each_see_the_other_job_ahead_and_refusals_lose_nothing(self):
        self.rig.ready(self.alice)
        self.rig.stall_device(20000)
        one = plan_from_steps([{"op": "set_pressure", "kpa": 0.3}])
        a1 = self.alice.submit(one, "alice 1")
        self.assertTrue(wait_until(lambda: self.alice.job(a1.id).state == 2))  # running
        bob_says = self.rig.cli("submit", self._plan_file([{"op": "set_pressure", "kpa": 0.2}]), "--json",
                                token="token-bob")
        self.assertEqual(bob_says.returncode, 0, bob_says.stderr)
        b1 = int(json.loads(bob_says.stdout)["id"])
        a2 = self.alice.submit(one, "alice 2")
        # Alice (Python) sees Bob's job (C++ CLI) ahead of her second; Bob saw hers ahead of his.
        jobs = {j.id: j for j in next(self.alice.watch(timeout=30 * TIME_SCALE)).jobs}
        self.assertLess(jobs[b1].position, jobs[a2.id].position)
        self.assertEqual(jobs[b1].owner, "bob")
        self.assertLess(jobs[a1.id].position, json.loads(bob_says.stdout)["position"])

        # Refused: an unsafe pressure, a wrong role, a bad token; the queue keeps its jobs.
        with self.assertRaises(ClientError) as e:
            self.alice.submit(plan_from_steps([{"op": "set_pressure", "kpa": 99.0}]))
        self.assertEqual(e.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("step 0", e.exception.details)
        with Client(self.rig.address, token="token-view") as viewer, self.assertRaises(ClientError) as e:
            viewer.submit(one)
        self.assertEqual(e.exception.code, grpc.StatusCode.PERMISSION_DENIED)
        with Client(self.rig.address, token="nope") as stranger, self.assertRaises(ClientError) as e:
            stranger.status()
        self.assertEqual(e.exception.code, grpc.StatusCode.UNAUTHENTICATED)
        self.assertEqual(queue_ids(self.alice), [a1.id, b1, a2.id])

    def _plan_file(self, steps):
        path = os.path.join(self.rig.folder, "plan.json")
        with open(path, "w") as f:
            json.dump({"steps": steps}, f)
        return path


class CalibrationTest(unittest.TestCase):
    """compare, fit and diagnose through the Python client, on two cheap
    sessions of demo-baseline and on the same with a camera tilt added by
    `hapticjam synth` (a known effect)."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig()
        cls.client = Client(cls.rig.address)
        cls.baseline = os.path.join(cls.rig.folder, "baseline")
        os.makedirs(cls.baseline)
        for name in ("unjammed-sweep", "mixed-1"):
            os.symlink(os.path.join(DEMO_BASELINE, name), os.path.join(cls.baseline, name))
        cls.tilted = os.path.join(cls.rig.folder, "tilted")
        made = subprocess.run([CLI, "synth", cls.baseline, "--out", cls.tilted, "--set", "sensor_tilt.offset_mm=1.5",
                               "--set", "sensor_tilt.tilt_x_mrad=15"],
                              capture_output=True, text=True, timeout=120 * TIME_SCALE)
        assert made.returncode == 0, made.stderr

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.rig.close()

    def test_fit_recovers_the_stated_mass_and_stiffness_and_reports_progress(self):
        events = []
        fit = self.client.fit(dataset_upload(self.baseline), holdout=["mixed-1"], on_progress=events.append,
                               timeout=240 * TIME_SCALE)
        values = {p.name: p for p in fit.parameters}
        self.assertAlmostEqual(values["mass_kg"].value / 0.52, 1.0, delta=0.03)
        self.assertAlmostEqual(values["spring_k"].value / 58.0, 1.0, delta=0.03)
        self.assertLess(values["spring_k"].ci95_low, values["spring_k"].value)
        self.assertTrue(fit.HasField("heldout_rmse_mm"))
        self.assertLess(fit.heldout_rmse_mm, 1.2 * fit.noise_floor_mm)
        self.assertTrue(events)
        for e in events:
            self.assertLessEqual(e.done, e.total)
        # The returned params.json drives a compare at the noise floor.
        compared = self.client.compare(dataset_upload(self.baseline), params_json=fit.params_json, timeout=120 * TIME_SCALE)
        self.assertLess(compared.rmse_mm, 1.1 * compared.noise_floor_mm)
        summary = json.loads(compared.summary_json)
        self.assertEqual({s["name"] for s in summary["sessions"]}, {"unjammed-sweep", "mixed-1"})
        # A heat map per capture, named in summary.json and embedded in report.html.
        images = [c["image"] for s in summary["sessions"] for c in s["captures"]]
        self.assertEqual([m.path for m in compared.maps], images)
        for m in compared.maps:
            self.assertTrue(m.content.startswith(b"\x89PNG"), m.path)
        self.assertEqual(compared.report_html.count("data:image/png;base64,"), len(images))

    def test_diagnose_finds_the_camera_tilt_that_synth_added(self):
        result = self.client.diagnose(dataset_upload(self.tilted), effects=["sensor_tilt", "bending"], timeout=240 * TIME_SCALE)
        self.assertEqual(list(result.verdict), ["sensor_tilt"])
        self.assertGreater(result.baseline_rmse_mm, 1.2 * result.noise_floor_mm)
        self.assertLess(result.final_rmse_mm, 1.1 * result.noise_floor_mm)
        diagnosis = json.loads(result.diagnosis_json)
        self.assertEqual(diagnosis["ranking"][0]["effect"], "sensor_tilt")
        # report.html as `hapticjam diagnose` writes it: the verdict and the
        # error ladder (baseline, + sensor_tilt; fitted and held out).
        self.assertIn("The data need: sensor_tilt.", result.report_html)
        self.assertEqual(result.report_html.count("<svg"), 1)
        self.assertEqual(result.report_html.count("<circle"), 2 * len(diagnosis["ladder"]))

    def test_a_malformed_session_is_an_invalid_argument_naming_it(self):
        dataset = dataset_upload(self.baseline)
        dataset.sessions[0].session_json = "{"
        with self.assertRaises(ClientError) as raised:
            self.client.diagnose(dataset, timeout=60 * TIME_SCALE)
        self.assertEqual(raised.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn(dataset.sessions[0].name, raised.exception.details)


class TlsTest(unittest.TestCase):
    """--tls-cert/--tls-key: a client that trusts the certificate is served;
    a plaintext client is not."""

    def test_a_trusting_client_is_served_and_plaintext_is_refused(self):
        folder = tempfile.mkdtemp(prefix="hj_py_tls_")
        cert, key = os.path.join(folder, "cert.pem"), os.path.join(folder, "key.pem")
        subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
                        "-keyout", key, "-out", cert, "-subj", "/CN=localhost",
                        "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1"],
                       check=True, capture_output=True)
        rig = Rig(["--tls-cert", cert, "--tls-key", key])
        try:
            with open(cert, "rb") as f:
                trusted = Client(rig.address, root_certificates=f.read())
            try:
                self.assertIn("algorithm2", [p for p in trusted.planners().planners])
            finally:
                trusted.close()
            plain = Client(rig.address)
            try:
                with self.assertRaises(ClientError) as refused:
                    plain.planners(timeout=5)
                self.assertEqual(refused.exception.code, grpc.StatusCode.UNAVAILABLE)
            finally:
                plain.close()
        finally:
            rig.close()


if __name__ == "__main__":
    unittest.main(verbosity=2)
