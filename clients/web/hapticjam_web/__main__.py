"""hapticjam-web: the browser viewer's gateway (docs/web.md).

    PYTHONPATH=build/clients/python:clients/python:clients/web python3 -m hapticjam_web \\
        --server 127.0.0.1:7600 --listen 127.0.0.1:8080 \\
        --map volcano=../shared/data/dem/volcano_maunga_whau.csv --dataset demo=../shared/data/sessions/demo-baseline
"""

import argparse
import os
import sys

from .calls import Gateway
from .web_server import THREE_DIR, make_server

LOOPBACK = ("127.0.0.1", "localhost", "::1", "[::1]")


def name_equals_path(flag, kind):
    def parse(text):
        name, eq, path = text.partition("=")
        if not eq or not name or not path:
            raise argparse.ArgumentTypeError(f"{flag} needs NAME={kind}, got {text!r}")
        if not os.path.exists(path):
            raise argparse.ArgumentTypeError(f"{flag} {text!r}: no such {kind.lower()} {path!r}")
        return name, path
    return parse


def parse_args(argv):
    p = argparse.ArgumentParser(prog="hapticjam-web", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--server", required=True, help="HOST:PORT of hapticjam-server (its gRPC address)")
    p.add_argument("--listen", default="127.0.0.1:8080",
                   help="HOST:PORT to serve the pages on (default 127.0.0.1:8080; port 0 picks a free one)")
    p.add_argument("--map", action="append", default=[], type=name_equals_path("--map", "FILE"),
                   help="NAME=FILE: the file of a server map, so that the pages can draw it (repeatable)")
    p.add_argument("--dataset", action="append", default=[], type=name_equals_path("--dataset", "FOLDER"),
                   help="NAME=FOLDER: a measurement dataset the Workbench page may pick (repeatable)")
    p.add_argument("--three-dir", default=THREE_DIR, help=f"three.js (Debian's libjs-three; default {THREE_DIR})")
    p.add_argument("--allow-remote", action="store_true",
                   help="serve on a non-loopback address (tokens then cross the network in clear HTTP)")
    args = p.parse_args(argv)
    host, colon, port = args.listen.rpartition(":")
    if not colon or not port.isdigit():
        p.error(f"--listen needs HOST:PORT, got {args.listen!r}")
    if host not in LOOPBACK and not args.allow_remote:
        p.error(f"--listen {args.listen}: not a loopback address; add --allow-remote to serve other machines")
    args.host, args.port = host.strip("[]"), int(port)
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if not os.path.isfile(os.path.join(args.three_dir, "build", "three.module.js")):
        print(f"hapticjam-web: no three.js in {args.three_dir} (apt-get install libjs-three); "
              "the pages draw surfaces on a 2-D canvas instead", file=sys.stderr)
    gateway = Gateway(args.server, maps=dict(args.map), datasets=dict(args.dataset))
    server = make_server(gateway, args.host, args.port, args.three_dir, loopback_only=not args.allow_remote)
    host = args.host if ":" not in args.host else f"[{args.host}]"
    print(f"hapticjam-web listening on http://{host}:{server.server_address[1]}/ (server {args.server})", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        gateway.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
