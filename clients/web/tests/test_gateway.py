"""The gateway without a browser: its HTTP answers to good and bad requests,
against a real server (clients/web/tests/rig.py). Run by ctest (web_gateway)."""

import base64
import http.client
import json
import os
import re
import signal
import subprocess
import tempfile
import time
import unittest

from rig import DEM, SERVER, SHARED, TOKENS, Stack


class GatewayTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.stack = Stack()
        cls.host, cls.port = cls.stack.url[len("http://"):-1].split(":")

    @classmethod
    def tearDownClass(cls):
        cls.stack.close()

    def call(self, method, path, body=None, token=None, api_header=True, host=None):
        connection = http.client.HTTPConnection(self.host, int(self.port), timeout=120)
        headers = {"Content-Type": "application/json", "Host": host or f"{self.host}:{self.port}"}
        if api_header:
            headers["X-Hapticjam-Web"] = "1"
        if token:
            headers["Authorization"] = "Bearer " + token
        connection.request(method, path, body=None if body is None else json.dumps(body), headers=headers)
        response = connection.getresponse()
        data = response.read()
        connection.close()
        return response.status, data

    def test_roles_come_from_the_server(self):
        for role, token in TOKENS.items():
            status, data = self.call("GET", "/api/role", token=token)
            self.assertEqual(status, 200)
            # The API cannot tell an admin from an operator without acting.
            self.assertEqual(json.loads(data)["role"], "preview" if role == "preview" else "operator")
        self.assertEqual(json.loads(self.call("GET", "/api/role")[1])["role"], "none")

    def test_a_refusal_is_the_servers_status_in_words(self):
        status, data = self.call("POST", "/api/device/submit", {"steps": [{"op": "capture"}]}, token=TOKENS["preview"])
        self.assertEqual(status, 403)
        error = json.loads(data)["error"]
        self.assertEqual((error["call"], error["code"]), ("SubmitJob", "PERMISSION_DENIED"))
        self.assertIn("needs operator", error["message"])
        status, data = self.call("GET", "/api/info", token="not-a-token")
        self.assertEqual((status, json.loads(data)["error"]["code"]), (401, "UNAUTHENTICATED"))

    def test_bad_bodies_name_the_field(self):
        status, data = self.call("POST", "/api/preview", {"rows": 3, "cols": "four", "goal": {"map": "volcano"}},
                                 token=TOKENS["preview"])
        self.assertEqual(status, 400)
        self.assertIn("request.cols must be int", json.loads(data)["error"]["message"])
        status, data = self.call("POST", "/api/preview", {"rows": 3, "cols": 4, "goal": {"map": "nowhere"}},
                                 token=TOKENS["preview"])
        self.assertEqual(status, 400)
        self.assertIn("nowhere", json.loads(data)["error"]["message"])
        status, data = self.call("POST", "/api/plan", {"rows": 3, "cols": 4, "goal": {"file": {"name": "a.csv",
                                 "content_b64": "%%%"}}}, token=TOKENS["preview"])
        self.assertEqual(status, 400)
        self.assertIn("goal.file.content_b64 is not base64", json.loads(data)["error"]["message"])

    def test_out_of_range_numbers_and_wrong_lists_are_bad_requests(self):
        status, data = self.call("POST", "/api/preview", {"rows": 1 << 40, "cols": 4, "goal": {"map": "volcano"}},
                                 token=TOKENS["preview"])
        self.assertEqual(status, 400, data)
        status, data = self.call("POST", "/api/calibration/compare", {"dataset": "demo-two", "options": {"effects": [1]}},
                                 token=TOKENS["preview"])
        self.assertEqual(status, 400, data)
        self.assertIn("options.effects", json.loads(data)["error"]["message"])

    def test_api_calls_without_the_pages_header_are_refused(self):
        status, data = self.call("POST", "/api/device/stop", {}, token=TOKENS["admin"], api_header=False)
        self.assertEqual(status, 403)
        self.assertIn("X-Hapticjam-Web", json.loads(data)["error"]["message"])

    def test_api_calls_naming_another_host_are_refused(self):
        """A page of another site whose name was made to resolve to 127.0.0.1 sends its own name as Host."""
        status, data = self.call("POST", "/api/device/stop", {}, token=TOKENS["admin"], host="evil.example:80")
        self.assertEqual(status, 403)
        self.assertIn("loopback", json.loads(data)["error"]["message"])
        self.assertEqual(self.call("GET", "/api/info", token=TOKENS["preview"], host=f"localhost:{self.port}")[0], 200)

    def test_static_files_stay_inside_their_folders(self):
        self.assertEqual(self.call("GET", "/")[0], 200)
        self.assertEqual(self.call("GET", "/three/build/three.module.js")[0], 200)
        self.assertEqual(self.call("GET", "/static/../hapticjam_web/calls.py")[0], 404)
        self.assertEqual(self.call("GET", "/three/../../../etc/passwd")[0], 404)

    def test_the_plan_stream_is_json_lines_ending_in_the_result(self):
        status, data = self.call("POST", "/api/plan", {"rows": 3, "cols": 4, "segments": 2, "goal": {"map": "volcano"}},
                                 token=TOKENS["preview"])
        self.assertEqual(status, 200)
        events = [json.loads(line) for line in data.decode().splitlines()]
        self.assertIn("result", events[-1])
        self.assertEqual(len(events[-1]["result"]["predicted"]["heights_mm"]), 7 * 9)
        self.assertTrue(any("snapshot" in e for e in events))

    def test_an_uploaded_goal_is_the_same_goal_as_the_servers_map(self):
        """The DEM's bytes with its sidecar preview like the map made from the same file."""
        with open(DEM, "rb") as f:
            content = base64.b64encode(f.read()).decode()
        with open(os.path.splitext(DEM)[0] + ".json") as f:
            sidecar = f.read()
        region = [0.1, 0.2, 0.8, 0.9]
        answers = []
        for goal in ({"file": {"name": "volcano.csv", "content_b64": content, "sidecar_json": sidecar}, "region": region},
                     {"map": "volcano", "region": region}):
            status, data = self.call("POST", "/api/preview", {"rows": 3, "cols": 4, "goal": goal}, token=TOKENS["preview"])
            self.assertEqual(status, 200, data)
            answers.append(json.loads(data))
        self.assertEqual(answers[0]["goal_heights_mm"], answers[1]["goal_heights_mm"])
        self.assertEqual(answers[0]["correlation"], answers[1]["correlation"])

    def test_a_mesh_goal_previews(self):
        with open(os.path.join(SHARED, "data", "mesh", "openscad_letterblock.stl"), "rb") as f:
            content = base64.b64encode(f.read()).decode()
        status, data = self.call("POST", "/api/preview", {"rows": 3, "cols": 4, "goal": {
            "file": {"name": "block.stl", "content_b64": content}}}, token=TOKENS["preview"])
        self.assertEqual(status, 200, data)
        self.assertEqual(len(json.loads(data)["predicted"]["heights_mm"]), 7 * 9)


class ServerHttpFlagTest(unittest.TestCase):
    """hapticjam-server --http starts the gateway beside itself and stops it on shutdown."""

    def test_the_server_serves_the_viewer_and_takes_it_down_with_it(self):
        folder = tempfile.mkdtemp(prefix="hj_web_http_")
        server = subprocess.Popen([SERVER, "--listen", "127.0.0.1:0", "--db", os.path.join(folder, "queue.db"),
                                   "--map", f"volcano={DEM}", "--http", "127.0.0.1:0"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        try:
            port = None
            deadline = time.monotonic() + 60
            while port is None and time.monotonic() < deadline:
                m = re.search(r"hapticjam-web listening on http://127\.0\.0\.1:(\d+)/", server.stdout.readline())
                port = int(m.group(1)) if m else None
            self.assertIsNotNone(port, "no address from the viewer")
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
            connection.request("GET", "/api/info", headers={"X-Hapticjam-Web": "1"})
            info = json.loads(connection.getresponse().read())
            connection.close()
            self.assertEqual(info["maps"], ["volcano"])
            self.assertEqual(list(info["map_files"]), ["volcano"])
        finally:
            server.send_signal(signal.SIGTERM)
            self.assertEqual(server.wait(timeout=30), 0)
            server.stdout.close()
        with self.assertRaises(OSError):  # the gateway went with it
            http.client.HTTPConnection("127.0.0.1", port, timeout=5).request("GET", "/")

    def test_http_off_loopback_needs_auth(self):
        out = subprocess.run([SERVER, "--listen", "127.0.0.1:0", "--http", "0.0.0.0:8080"], capture_output=True,
                             text=True, timeout=30)
        self.assertEqual(out.returncode, 2)
        self.assertIn("--http 0.0.0.0:8080 is not a loopback address", out.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
