"""The HTTP side: static pages, three.js from Debian's libjs-three, and the
/api/ routes (JSON in, JSON or newline-delimited JSON streams out). The
browser's `Authorization: Bearer TOKEN` is passed on to every gRPC call."""

import json
import mimetypes
import os
import select
import socket
import threading
import urllib.parse
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import grpc

from . import convert
from .calls import CallError
from .http_errors import error_body, http_status

STATIC_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "static")
THREE_DIR = "/usr/share/javascript/three"  # Debian: libjs-three
MAX_BODY_BYTES = 96 << 20  # a 64 MiB goal, base64-encoded
LOOPBACK_NAMES = {"127.0.0.1", "localhost", "[::1]"}
# Pages send this header with every API call: a plain cross-site form cannot,
# so another site open in the same browser cannot drive the device.
API_HEADER = "X-Hapticjam-Web"

# The gRPC call behind each streaming route, to name it in errors.
STREAM_CALLS = {"/api/plan": "Plan", "/api/queue/watch": "WatchQueue", "/api/calibration/compare": "Compare",
                "/api/calibration/fit": "Fit", "/api/calibration/diagnose": "Diagnose"}

mimetypes.add_type("text/javascript", ".js")
mimetypes.add_type("text/javascript", ".mjs")


def serve_file(handler, root, relative):
    """Sends root/relative if it lies inside root, else 404."""
    root = os.path.realpath(root)
    path = os.path.realpath(os.path.join(root, relative))
    if not (path == root or path.startswith(root + os.sep)) or not os.path.isfile(path):
        return handler.send_json(404, error_body("GET", "NOT_FOUND", f"no file {relative!r}"))
    with open(path, "rb") as f:
        data = f.read()
    handler.send_response(200)
    handler.send_header("Content-Type", mimetypes.guess_type(path)[0] or "application/octet-stream")
    handler.send_header("Content-Length", str(len(data)))
    handler.send_header("Cache-Control", "no-cache")
    handler.end_headers()
    handler.wfile.write(data)


def cancel_when_client_leaves(connection, call, done):
    """Cancels the gRPC `call` once the browser closes its connection (a
    stream may sit idle for long, so a failed write alone would notice late)."""
    while not done.is_set():
        readable, _, _ = select.select([connection], [], [], 0.5)
        if readable:
            try:
                if connection.recv(1, socket.MSG_PEEK) == b"":
                    call.cancel()
                    return
            except OSError:
                call.cancel()
                return
            done.wait(0.5)  # data from the browser while streaming: ignore it


class Handler(BaseHTTPRequestHandler):
    gateway = None      # set by make_server
    three_dir = THREE_DIR
    loopback_only = True  # API calls must name a loopback Host (a DNS-rebinding page names its own)
    protocol_version = "HTTP/1.1"

    def log_message(self, fmt, *args):  # one short line per request on stderr
        if os.environ.get("HJ_WEB_QUIET") != "1":
            super().log_message(fmt, *args)

    # -- plumbing --

    def send_json(self, status, doc):
        data = json.dumps(doc).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(data)

    def host_name(self):
        """The Host header without its port ("[::1]:8080" -> "[::1]")."""
        host = self.headers.get("Host", "")
        return host if host.endswith("]") else host.rpartition(":")[0] or host

    def token(self):
        auth = self.headers.get("Authorization", "")
        return auth[len("Bearer "):].strip() if auth.startswith("Bearer ") else ""

    def body(self):
        length = int(self.headers.get("Content-Length") or 0)
        if length > MAX_BODY_BYTES:
            raise convert.BadRequest(f"request body of {length} bytes is over the gateway's {MAX_BODY_BYTES} bytes")
        raw = self.rfile.read(length) if length else b"{}"
        try:
            doc = json.loads(raw)
        except ValueError as e:
            raise convert.BadRequest(f"request body is not JSON: {e}") from None
        if not isinstance(doc, dict):
            raise convert.BadRequest("request body must be a JSON object")
        return doc

    def stream(self, name, call_and_convert):
        """Relays a gRPC stream as newline-delimited JSON, one event a line;
        a failure after the first line is sent as a last {"error": ...} line."""
        call, to_json = call_and_convert
        done = threading.Event()
        threading.Thread(target=cancel_when_client_leaves, args=(self.connection, call, done), daemon=True).start()
        try:
            first = next(call, None)  # before the headers, so that a refusal gets its HTTP status
        except grpc.RpcError as e:
            done.set()
            return self.send_json(http_status(e.code()), error_body(name, e.code(), e.details()))
        self.send_response(200)
        self.send_header("Content-Type", "application/x-ndjson")
        self.send_header("Cache-Control", "no-store")
        self.send_header("Transfer-Encoding", "chunked")
        self.end_headers()
        try:
            if first is not None:
                self.write_chunk(to_json(first))
                for event in call:
                    self.write_chunk(to_json(event))
        except grpc.RpcError as e:
            if e.code() != grpc.StatusCode.CANCELLED or not done.is_set():
                self.write_chunk(error_body(name, e.code(), e.details()))
        except (BrokenPipeError, ConnectionResetError):
            call.cancel()
            self.close_connection = True
            return
        finally:
            done.set()
        self.wfile.write(b"0\r\n\r\n")

    def write_chunk(self, doc):
        data = (json.dumps(doc) + "\n").encode()
        self.wfile.write(f"{len(data):x}\r\n".encode() + data + b"\r\n")
        self.wfile.flush()

    # -- routes --

    def do_GET(self):
        url = urllib.parse.urlsplit(self.path)
        path, query = url.path, urllib.parse.parse_qs(url.query)
        if path in ("/", "/index.html"):
            return serve_file(self, STATIC_DIR, "index.html")
        if path.startswith("/static/"):
            return serve_file(self, STATIC_DIR, path[len("/static/"):])
        if path.startswith("/three/"):
            return serve_file(self, self.three_dir, path[len("/three/"):])
        if path.startswith("/api/maps/"):
            return self.map_file(urllib.parse.unquote(path[len("/api/maps/"):]))
        g = self.gateway
        routes = {
            "/api/info": lambda: g.info(self.token()),
            "/api/role": lambda: g.role(self.token()),
            "/api/device/status": lambda: g.status(self.token()),
        }
        streams = {"/api/queue/watch": lambda: g.watch_stream(int(query.get("recent", ["8"])[0]), self.token())}
        self.answer(path, routes, streams)

    def do_POST(self):
        g = self.gateway
        path = urllib.parse.urlsplit(self.path).path
        routes = {
            "/api/preview": lambda: g.preview(self.body(), self.token()),
            "/api/device/submit": lambda: g.submit(self.body(), self.token()),
            "/api/device/cancel": lambda: g.cancel(self.body(), self.token()),
            "/api/device/stop": lambda: g.stop(self.body(), self.token()),
            "/api/device/resume": lambda: g.resume(self.token()),
        }
        streams = {"/api/plan": lambda: g.plan_stream(self.body(), self.token())}
        for kind in ("compare", "fit", "diagnose"):
            streams["/api/calibration/" + kind] = lambda kind=kind: g.calibration_stream(kind, self.body(), self.token())
        self.answer(path, routes, streams)

    def answer(self, path, routes, streams):
        if path not in routes and path not in streams:
            return self.send_json(404, error_body(path, "NOT_FOUND", f"no route {self.command} {path}"))
        if self.loopback_only and self.host_name() not in LOOPBACK_NAMES:
            return self.send_json(403, error_body(path, "FORBIDDEN", f"Host {self.headers.get('Host')!r}: this viewer "
                                                                     "answers only to a loopback address"))
        if self.headers.get(API_HEADER) != "1":
            return self.send_json(403, error_body(path, "FORBIDDEN", f"API calls need the header {API_HEADER}: 1 "
                                                                     "(the pages send it)"))
        try:
            if path in streams:
                return self.stream(STREAM_CALLS[path], streams[path]())
            self.send_json(200, routes[path]())
        except convert.BadRequest as e:
            self.send_json(400, error_body(path, "INVALID_ARGUMENT", str(e)))
        except CallError as e:
            self.send_json(http_status(e.code), error_body(e.call, e.code, e.details))
        except grpc.RpcError as e:
            self.send_json(http_status(e.code()), error_body(path, e.code(), e.details()))
        except ValueError as e:  # protobuf's own checks, e.g. a number out of an int32's range
            self.send_json(400, error_body(path, "INVALID_ARGUMENT", str(e)))
        except Exception as e:  # a bug here: say so in words rather than drop the connection
            self.send_json(500, error_body(path, "INTERNAL", f"the gateway failed: {type(e).__name__}: {e}"))

    def map_file(self, rest):
        """/api/maps/NAME/file: the map's bytes; /api/maps/NAME/sidecar: its NAME.json ({} if none)."""
        name, _, part = rest.rpartition("/")
        if name not in self.gateway.maps or part not in ("file", "sidecar"):
            return self.send_json(404, error_body("map", "NOT_FOUND",
                                                  f"the gateway has no file for map {name!r} (start it with --map NAME=FILE)"))
        path = self.gateway.maps[name]
        if part == "sidecar":
            side = os.path.splitext(path)[0] + ".json"
            return serve_file(self, os.path.dirname(side), os.path.basename(side)) if os.path.isfile(side) \
                else self.send_json(200, {})
        serve_file(self, os.path.dirname(path), os.path.basename(path))


def make_server(gateway, host, port, three_dir=THREE_DIR, loopback_only=True):
    handler = type("BoundHandler", (Handler,), {"gateway": gateway, "three_dir": three_dir,
                                                "loopback_only": loopback_only})
    server = ThreadingHTTPServer((host, port), handler)
    server.daemon_threads = True
    return server
