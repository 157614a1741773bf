#!/usr/bin/env python3
"""The render job's acceptance figures (docs/render.md): device-makeable goals
on an emulator whose model the planner was not given, closed loop against open
loop, as a Markdown table.

For each case it starts hapticjam-device-emulator with the case's params
(effects the planner does not know, a finer mesh, a 1 mm camera), makes each
goal with the emulator's own model from a known sequence (sent on a raw
protocol line, read back with `truth` at the planner's mesh points, vented),
starts hapticjam-server on it, runs `hapticjam remote render --json` and
reads the true surface afterwards.

  scripts/render_acceptance.py --build build [--sizes 3x4,6x8] [--iterations 5] [--cases stiffening,...]
                               [--goals ridge,...,PATH] [--corrections both,targets,model] [--planner NAME]
                               [--device-segments P]

A goal that is a path (../shared/data/dem/volcano_maunga_whau.csv) is rendered
as the CLI takes it, at the default relief; its true-surface MAE is against
the goal at the planner's mesh points that `remote render --out` writes.

Besides the table, one line per run lists the MAE and r of every iteration,
its planning and fitting seconds and the model fitted last (correction
model or both): on stderr as each run ends, and on stdout after the table.
"""
import argparse
import json
import os
import re
import socket
import subprocess
import sys
import tempfile
import time

CASES = {
    "stiffening": {"stiffening": {"beta": 30}},
    "soft-middle": {"cell_stiffness": {"bulge": -0.3}},
    "both": {"stiffening": {"beta": 30}, "cell_stiffness": {"bulge": -0.3}},
    "tilt": {"stiffening": {"beta": 30}, "sensor_tilt": {"tilt_x_mrad": 15, "tilt_y_mrad": -10}},
}


def sequences(rows, cols):
    """Three known sequences per array size: rising pressure, jams and pins on the way.
    Pressures are for 3 x 4. Above levelling (the pressure that carries the membrane's
    weight, the same at every size) a dome's height over its span goes as
    ((P - P_level) L / k)^(1/3), so the same shapes scaled with the array, as the paper
    scales goals, take P_level + (P - P_level) x 3 / rows (6 x 8: 1200 Pa -> 756 Pa)."""
    r2, c2 = rows // 2, cols // 2
    scale = 3.0 / rows
    return {name: [scaled(c, scale) for c in seq] for name, seq in {
        "ridge": ["set_pressure 1200", "jam 0 1", f"pin 1 1", "set_pressure 2400", f"jam {rows - 2} {cols - 2}",
                  f"jam {rows - 1} 0", "set_pressure 3000"],
        "terrace": ["set_pressure 800"] + [f"jam 0 {c}" for c in range(cols)] +
                   ["set_pressure 2000", f"pin {r2} {c2}", "set_pressure 3200"],
        "saddle": ["set_pressure 1500", f"jam {r2} {c2}", f"jam 0 {cols - 1}", "set_pressure 2800",
                   f"pin 1 {cols - 2}"],
    }.items()}


# The membrane's weight per area in the model's defaults (0.55 kg per 12 cells of
# 38 mm, docs/model.md): below it the membrane sags, above it domes.
LEVELLING_PA = 0.55 / 12 * 9.81 / 0.038 ** 2


def scaled(command, scale):
    words = command.split(" ")
    if words[0] != "set_pressure":
        return command
    return f"set_pressure {LEVELLING_PA + (float(words[1]) - LEVELLING_PA) * scale:.0f}"


class Line:
    """A raw connection to the emulator (src/device/PROTOCOL.md)."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=120)
        self.sock.settimeout(0.2)
        self.buffer = b""
        self.id = 0
        self.pings = 1 << 40  # ids of the heartbeat, apart from the commands'

    def _receive(self):
        """More bytes; a ping while waiting, so the emulator's watchdog sees a live line."""
        try:
            chunk = self.sock.recv(1 << 20)
        except socket.timeout:
            self.pings += 1
            self.sock.sendall(f"{self.pings} ping\n".encode())
            return
        if not chunk:
            raise RuntimeError("the emulator closed the line")
        self.buffer += chunk

    def request(self, command):
        self.id += 1
        self.sock.sendall(f"{self.id} {command}\n".encode())
        while True:
            nl = self.buffer.find(b"\n")
            if nl >= 0:
                line, self.buffer = self.buffer[:nl].decode(), self.buffer[nl + 1:]
                if line.split(" ")[1:2] == [str(self.id)]:
                    if not line.startswith("ok"):
                        raise RuntimeError(f"{command}: {line}")
                    return line[len(f"ok {self.id}"):].strip()
                continue
            self._receive()

    def close(self):
        self.sock.close()


def at_mesh_points(payload, rows, cols, p, cell_mm=38.0):
    """A `frame` payload bilinearly sampled at the rest points (row i along +y); an empty
    sample on the clamped edge is its height, 0."""
    words = payload.split(" ")
    nx, ny = int(words[1]), int(words[2])
    x0, y0, dx, dy = map(float, words[3:7])
    v = [float(s) for s in words[7].split(",")]
    h = cell_mm / p
    out = []
    for i in range(rows * p + 1):
        row = []
        for j in range(cols * p + 1):
            u, w = (j * h - x0) / dx, (i * h - y0) / dy
            ix, iy = min(max(int(u), 0), nx - 2), min(max(int(w), 0), ny - 2)
            fx, fy = min(max(u - ix, 0), 1), min(max(w - iy, 0), 1)
            s = wt = 0.0
            for ddy in (0, 1):
                for ddx in (0, 1):
                    z = v[(iy + ddy) * nx + ix + ddx]
                    k = (fx if ddx else 1 - fx) * (fy if ddy else 1 - fy)
                    if z == z and k > 0:
                        s, wt = s + k * z, wt + k
            on_edge = i in (0, rows * p) or j in (0, cols * p)
            # The clamped edge is at 0; a camera sample beside it can be empty where the
            # membrane has moved inward (the frame's highest-triangle rule finds nothing there).
            row.append(s / wt if wt > 0 else 0.0 if on_edge else float("nan"))
        out.append(row)
    return out


def mae(a, b):
    d = [abs(x - y) for ra, rb in zip(a, b) for x, y in zip(ra, rb) if x == x and y == y]
    return sum(d) / len(d)


def start(argv, pattern, log):
    proc = subprocess.Popen(argv, stdout=open(log + ".out", "w"), stderr=open(log + ".err", "w"))
    end = time.time() + 60
    while time.time() < end:
        m = re.search(pattern, open(log + ".out").read())
        if m:
            return proc, int(m.group(1))
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    raise RuntimeError(f"{argv[0]} did not start: " + open(log + ".err").read())


def read_points(path):
    """A frame CSV written by `remote render --out` (goal.csv): row i of the mesh first."""
    return [[float(v) for v in line.split(",")] for line in open(path) if line.strip()]


def run_case(build, work, case, size, goal_name, commands, iterations, noise, gain, planner, correction,
             device_segments=8, goal_path=None):
    """One render. With goal_path, the goal is that file as the CLI takes it (a shared DEM or mesh at
    the default relief); otherwise the emulator makes it from `commands` and it is rendered in absolute mm."""
    rows, cols = size
    params = os.path.join(work, "device.json")
    with open(params, "w") as f:
        json.dump({"format": "hapticjam.params/1", "effects": CASES[case]}, f)
    emulator, port = start([os.path.join(build, "src/device/hapticjam-device-emulator"), "--listen", "127.0.0.1:0",
                            "--rows", str(rows), "--cols", str(cols), "--segments", str(device_segments),
                            "--params", params,
                            "--noise-mm", str(noise), "--seed", "11"],
                           r"listening on 127\.0\.0\.1:(\d+)", os.path.join(work, "emulator"))
    server = None
    try:
        line = Line(port)
        if goal_path:
            goal_file, heights = goal_path, []
        else:
            for c in commands:
                line.request(c)
            goal = at_mesh_points(line.request("truth"), rows, cols, 4)
            line.request("vent")
            goal_file, heights = os.path.join(work, f"{goal_name}.csv"), ["--heights", "absolute"]
            with open(goal_file, "w") as f:
                for row in reversed(goal):
                    f.write(",".join(repr(z) for z in row) + "\n")
        db = os.path.join(work, "queue.db")
        for suffix in ("", "-wal", "-shm", ".lock"):
            if os.path.exists(db + suffix):
                os.remove(db + suffix)
        server, server_port = start([os.path.join(build, "server/hapticjam-server"), "--listen", "127.0.0.1:0",
                                     "--db", db, "--device", f"127.0.0.1:{port}"],
                                    r"listening on port (\d+)", os.path.join(work, "server"))
        address = f"127.0.0.1:{server_port}"
        cli = os.path.join(build, "hapticjam")
        for _ in range(300):
            status = subprocess.run([cli, "remote", "status", "--json", "--server", address], capture_output=True,
                                    text=True)
            if status.returncode == 0 and json.loads(status.stdout).get("connected"):
                break
            time.sleep(0.1)
        started = time.time()
        render = subprocess.run([cli, "remote", "render", goal_file, "--rows", str(rows), "--cols", str(cols),
                                 "--segments", "4", "--iterations", str(iterations), "--json", "--server", address,
                                 "--out", os.path.join(work, "render")] + heights + (["--gain", str(gain)] if gain else [])
                                + (["--planner", planner] if planner else [])
                                + (["--correction", correction] if correction else []), capture_output=True, text=True)
        seconds = time.time() - started
        if render.returncode != 0:
            raise RuntimeError(f"render failed ({render.returncode}): {render.stderr}")
        lines = [json.loads(s) for s in render.stdout.splitlines() if s.strip()]
        truth = at_mesh_points(line.request("truth"), rows, cols, 4)
        line.close()
        if goal_path:
            goal = read_points(os.path.join(work, "render", "goal.csv"))
        return {"iterations": lines[:-1], "result": lines[-1]["result"], "true_mae_mm": mae(goal, truth),
                "seconds": seconds}
    finally:
        for proc in (server, emulator):
            if proc:
                proc.terminate()  # the server vents; the emulator cuts a settle in progress short
                try:
                    proc.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()


def detail(run):
    """Per iteration: MAE / r, planning + fitting seconds; then the last fitted model."""
    parts = []
    for it in run["iterations"]:
        r = it.get("correlation")
        parts.append(f"{it['mae_mm']:.2f} mm / {'-' if r is None else f'{r:.3f}'} "
                     f"({it['planning_seconds']:.1f} + {it.get('fitting_seconds', 0.0):.1f} s)")
    text = "; ".join(parts)
    model = run["result"].get("model")
    if model:
        values = ", ".join(f"{k} {v:.4g}" for k, v in model["parameters"].items())
        text += f"; model: effects [{', '.join(model['effects'])}], {values}, RMSE {model['rmse_mm']:.2f} mm"
    return text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--sizes", default="3x4,6x8")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--goals", default="ridge,terrace,saddle",
                    help="device-made goals (ridge, terrace, saddle) and goal files (a path: a DEM or mesh, "
                         "rendered at the default relief)")
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--planner", default="", help="the server's planner for each iteration (default: the server's)")
    ap.add_argument("--noise-mm", type=float, default=1.0)
    ap.add_argument("--device-segments", type=int, default=8, help="the emulator's mesh (the planner's is 4)")
    ap.add_argument("--gain", type=float, default=0.0, help="of the target correction (0: the server's default)")
    ap.add_argument("--corrections", default="both",
                    help="comma-separated: targets, model, both, none (each case runs with each)")
    ap.add_argument("--json-out", help="also write every run's figures here")
    args = ap.parse_args()
    runs = []
    print("| array | device | goal | correction | open loop MAE (mm) | closed loop MAE (mm) | r open / closed | "
          "below open loop | iterations (best) | true surface MAE (mm) | render (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    details = []
    for size_text in args.sizes.split(","):
        size = tuple(int(v) for v in size_text.split("x"))
        for case in args.cases.split(","):
            for goal_name in args.goals.split(","):
                for correction in args.corrections.split(","):
                    goal_path = goal_name if os.sep in goal_name else None
                    if goal_path:
                        goal_name = os.path.splitext(os.path.basename(goal_path))[0]
                    label = f"{size_text} {case} {goal_name} {correction}"
                    with tempfile.TemporaryDirectory(prefix="hj_render_") as work:
                        try:
                            commands = None if goal_path else sequences(*size)[goal_name]
                            run = run_case(args.build, work, case, size, goal_name, commands,
                                           args.iterations, args.noise_mm, args.gain, args.planner, correction,
                                           args.device_segments, goal_path)
                        except RuntimeError as e:
                            print(f"| {size_text} | {case} | {goal_name} | {correction} | failed: {e} |||||||",
                                  flush=True)
                            continue
                    r = run["result"]
                    below = 100.0 * (1 - r["mae_mm"] / r["open_loop_mae_mm"]) if r["open_loop_mae_mm"] > 0 else 0.0
                    corr = lambda v: "-" if v is None else f"{v:.3f}"
                    print(f"| {size_text} | {case} | {goal_name} | {correction} | {r['open_loop_mae_mm']:.2f} | "
                          f"{r['mae_mm']:.2f} | {corr(r.get('open_loop_correlation'))} / {corr(r['correlation'])} | "
                          f"{below:.0f} % | {r['iterations']} ({r['best_iteration']}) | {run['true_mae_mm']:.2f} | "
                          f"{run['seconds']:.0f} |", flush=True)
                    details.append(f"{label}: " + detail(run))
                    print(f"<!-- {details[-1]} -->", file=sys.stderr, flush=True)
                    runs.append({"size": size_text, "case": case, "goal": goal_name, "correction": correction, **run})
    print()
    for line in details:
        print("- " + line)
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(runs, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
