"""A whole stack on loopback for the web tests: the device emulator, the
server (with an auth file and the volcano DEM as a map) and the gateway,
each printing its port; stopped by close()."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SERVER = os.environ["HJ_SERVER_PATH"]
EMULATOR = os.environ["HJ_EMULATOR_PATH"]
SHARED = os.environ["HJ_SHARED_DIR"]
WEB_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEM = os.path.join(SHARED, "data", "dem", "volcano_maunga_whau.csv")
DEMO_BASELINE = os.path.join(SHARED, "data", "sessions", "demo-baseline")
TOKENS = {"operator": "token-alice", "preview": "token-viewer", "admin": "token-root"}


def start(argv, folder, name, pattern, env=None):
    """Starts a program that prints its port; returns (process, port)."""
    out_path, err_path = os.path.join(folder, name + ".out"), os.path.join(folder, name + ".err")
    with open(out_path, "w") as out, open(err_path, "w") as err:
        process = subprocess.Popen(argv, stdout=out, stderr=err, env=env)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        with open(out_path) as out:
            m = re.search(pattern, out.read())
        if m:
            return process, int(m.group(1))
        if process.poll() is not None:
            break
        time.sleep(0.05)
    process.kill()
    with open(err_path) as err:
        raise RuntimeError(f"{name} did not start: " + err.read())


class Stack:
    def __init__(self):
        self.folder = tempfile.mkdtemp(prefix="hj_web_")
        auth = os.path.join(self.folder, "auth")
        with open(auth, "w") as f:
            f.write("alice operator token-alice\nviewer preview token-viewer\nroot admin token-root\n")
        # Two cheap sessions of demo-baseline as the Workbench's dataset (copies: a browser does not follow links).
        self.dataset = os.path.join(self.folder, "demo-two")
        os.makedirs(self.dataset)
        for name in ("unjammed-sweep", "mixed-1"):
            shutil.copytree(os.path.join(DEMO_BASELINE, name), os.path.join(self.dataset, name))
        self.processes = []
        emulator, emulator_port = start([EMULATOR, "--listen", "127.0.0.1:0", "--rows", "3", "--cols", "4"],
                                        self.folder, "emulator", r"listening on 127\.0\.0\.1:(\d+)")
        self.processes.append(emulator)
        server, port = start([SERVER, "--listen", "127.0.0.1:0", "--db", os.path.join(self.folder, "queue.db"),
                              "--device", f"127.0.0.1:{emulator_port}", "--auth", auth, "--workers", "1",
                              "--map", f"volcano={DEM}"], self.folder, "server", r"listening on port (\d+)")
        self.processes.append(server)
        self.grpc_address = f"127.0.0.1:{port}"
        env = dict(os.environ, PYTHONPATH=os.environ.get("PYTHONPATH", "") + os.pathsep + WEB_DIR, HJ_WEB_QUIET="1")
        gateway, web_port = start([sys.executable, "-m", "hapticjam_web", "--server", self.grpc_address,
                                   "--listen", "127.0.0.1:0", "--map", f"volcano={DEM}",
                                   "--dataset", f"demo-two={self.dataset}"],
                                  self.folder, "gateway", r"listening on http://127\.0\.0\.1:(\d+)/", env)
        self.processes.append(gateway)
        self.url = f"http://127.0.0.1:{web_port}/"

    def close(self):
        for p in reversed(self.processes):
            p.terminate()
        for p in self.processes:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
