"""kill -9 of hapticjam-server at random moments while clients submit, cancel
and resume jobs on the device emulator; after every kill and restart checks:
every acknowledged job present, in submission order; nothing left
`running`; the queue paused after a job was cut short; the device vented
before any job ran; PRAGMA integrity_check ok. Run by crash_campaign.sh."""
import json
import os
import random
import re
import signal
import sqlite3
import subprocess
import sys
import threading
import time

from hapticjam.v1 import plan_pb2
from hapticjam_client.client import Client, ClientError

RUNNING, INTERRUPTED = 2, 6  # JobState numbers (proto/hapticjam/v1/device_service.proto)


def plan(rng):
    steps = []
    for _ in range(rng.randint(2, 6)):
        kind = rng.choice(["p", "j", "c"])
        if kind == "p":
            steps.append(plan_pb2.Step(set_pressure=plan_pb2.SetPressure(kpa=round(rng.uniform(0.1, 1.5), 2))))
        elif kind == "j":
            step = plan_pb2.Step()
            step.jam.row, step.jam.col = rng.randint(0, 2), rng.randint(0, 3)
            steps.append(step)
        else:
            steps.append(plan_pb2.Step(capture=plan_pb2.CaptureStep()))
    return plan_pb2.Plan(steps=steps)


def start(command, banner, stderr):
    """Starts a process and returns it with the port its first stdout line names."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr, text=True)
    line = process.stdout.readline()
    found = re.search(banner, line)
    if not found:
        raise RuntimeError(f"{command[0]} did not start: {line!r}")
    return process, int(found.group(1))


class Clients:
    """Threads that submit, cancel and resume until told to stop; each keeps its acknowledged job ids."""

    def __init__(self, port, count, seed):
        self.port, self.done, self.threads = port, threading.Event(), []
        self.acknowledged = [[] for _ in range(count)]
        for i in range(count):
            thread = threading.Thread(target=self.work, args=(i, random.Random(seed * 100 + i)), daemon=True)
            thread.start()
            self.threads.append(thread)

    def work(self, index, rng):
        with Client(f"127.0.0.1:{self.port}") as client:
            while not self.done.is_set():
                try:
                    action = rng.random()
                    if action < 0.6:
                        self.acknowledged[index].append(client.submit(plan(rng), name=f"c{index}", timeout=5).id)
                    elif action < 0.8 and self.acknowledged[index]:
                        client.cancel(rng.choice(self.acknowledged[index]), timeout=5)
                    else:
                        client.resume(timeout=5)
                except ClientError:
                    pass  # paused, full, finished, or the server is gone
                except Exception:  # noqa: BLE001 - a dying server may fail a call in any way
                    pass
                time.sleep(rng.uniform(0.0, 0.05))

    def stop(self):
        self.done.set()
        for thread in self.threads:
            thread.join(10)


def check_database(db, acknowledged):
    problems = []
    with sqlite3.connect(db) as connection:
        if connection.execute("PRAGMA integrity_check").fetchone()[0] != "ok":
            problems.append("integrity_check is not ok")
        ids = {row[0] for row in connection.execute("SELECT id FROM jobs")}
    for client, jobs in enumerate(acknowledged):
        missing = [j for j in jobs if j not in ids]
        if missing:
            problems.append(f"client {client}: acknowledged jobs {missing[:5]} missing")
        if jobs != sorted(jobs):
            problems.append(f"client {client}: jobs out of submission order")
    return problems


def check_restart(client, log_lines, had_running):
    """The first queue state after a restart, before anyone resumed."""
    problems = []
    state = next(client.watch(recent_finished=0, timeout=10))
    if had_running and any(job.state == RUNNING for job in state.jobs):
        problems.append("a job is `running` after a restart that found one cut short")
    if had_running and not state.paused:
        problems.append("a job was cut short but the queue is not paused")
    return problems, state


def vented_first(log_path):
    """True if the server vented the device before it started any job."""
    events = []
    with open(log_path) as log:
        for line in log:
            try:
                events.append(json.loads(line).get("event"))
            except ValueError:
                continue
    if "job_started" not in events:
        return True
    return "device_vented" in events and events.index("device_vented") < events.index("job_started")


def main():
    build, kills, work = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    rng = random.Random(23)
    emulator_log_path = os.path.join(work, "emulator.log")
    emulator_log = open(emulator_log_path, "w")
    emulator, device_port = start([f"{build}/src/device/hapticjam-device-emulator", "--listen", "127.0.0.1:0"],
                                  r"127\.0\.0\.1:(\d+)", emulator_log)
    db = os.path.join(work, "queue.db")
    acknowledged = [[] for _ in range(3)]
    counts = {"kills": 0, "cut_short_jobs_found": 0, "acknowledged": 0, "lost": 0, "running_after_restart": 0, "not_paused_after_fault": 0,
              "not_vented_first": 0, "integrity_failures": 0, "problems": 0}
    try:
        for round_ in range(kills + 1):
            cut_short = []
            if os.path.exists(db):
                with sqlite3.connect(db) as connection:
                    cut_short = [r[0] for r in connection.execute("SELECT id FROM jobs WHERE state = ?", (RUNNING,))]
            log_path = os.path.join(work, f"server-{round_}.log")
            with open(log_path, "w") as log:
                server = subprocess.Popen([f"{build}/server/hapticjam-server", "--listen", "127.0.0.1:0", "--device",
                                           f"127.0.0.1:{device_port}", "--db", db, "--workers", "1",
                                           "--keep-jobs", "0", "--keep-days", "0"],
                                          stdout=subprocess.PIPE, stderr=log, text=True)
                line = server.stdout.readline()
                port = int(re.search(r"port (\d+)", line).group(1))
                with sqlite3.connect(db) as connection:
                    # Jobs `running` in the database once the server is up: the restart must have ended them all.
                    still_running = connection.execute("SELECT COUNT(*) FROM jobs WHERE state = ?",
                                                       (RUNNING,)).fetchone()[0]
                had_running = bool(cut_short)
                with Client(f"127.0.0.1:{port}") as client:
                    problems, _ = check_restart(client, None, had_running)
                if still_running and had_running:
                    problems.append(f"{still_running} jobs still `running` in the database after the restart")
                counts["cut_short_jobs_found"] += had_running
                counts["running_after_restart"] += any("running" in p for p in problems)
                counts["not_paused_after_fault"] += any("paused" in p for p in problems)
                if round_ == kills:
                    server.terminate()
                    server.wait(30)
                    break
                clients = Clients(port, 3, round_)
                time.sleep(rng.uniform(0.2, 1.5))
                server.send_signal(signal.SIGKILL)
                server.wait(30)
                clients.stop()
                counts["kills"] += 1
            for i in range(3):
                acknowledged[i] += clients.acknowledged[i]
            db_problems = check_database(db, acknowledged)
            counts["lost"] += sum("missing" in p for p in db_problems)
            counts["integrity_failures"] += sum("integrity" in p for p in db_problems)
            counts["not_vented_first"] += not vented_first(log_path)
            for p in problems + db_problems:
                print(f"round {round_}: {p}", flush=True)
            counts["problems"] += len(problems) + len(db_problems) + (not vented_first(log_path))
    finally:
        emulator.terminate()
        emulator.wait(30)
        emulator_log.close()
    counts["acknowledged"] = sum(len(a) for a in acknowledged)
    with open(emulator_log_path) as log:
        counts["device_vented_on_closed_connection"] = sum("vented (connection closed)" in line for line in log)
    print("[crash campaign] " + ", ".join(f"{k} {v}" for k, v in counts.items()), flush=True)
    return 0 if counts["problems"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
