#!/usr/bin/env python3
"""CAD preview: send a mesh (STL, OBJ, PLY, glTF/GLB, 3MF) to hapticjam-server
and save a PNG of the surface the display is predicted to make of it.

    PYTHONPATH=build/clients/python:clients/python python3 clients/python/examples/cad_preview.py \
        --server 127.0.0.1:50051 ../shared/data/mesh/stanford_bunny.stl --up-axis y --out bunny.png
"""

import argparse
import sys
import time

from hapticjam_client import Client, ClientError, Surface, file_goal, write_png


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh", help="the part's mesh file")
    p.add_argument("--server", required=True, help="HOST:PORT of hapticjam-server")
    p.add_argument("--token", default=None, help="bearer token (preview role)")
    p.add_argument("--rows", type=int, default=3)
    p.add_argument("--cols", type=int, default=4)
    p.add_argument("--segments", type=int, default=0, help="mesh segments per cell edge (default: coarse preview)")
    p.add_argument("--up-axis", default="", help="the mesh's up axis: x, y, z, -x, -y, -z (default z)")
    p.add_argument("--out", default="preview.png", help="PNG to write")
    args = p.parse_args()

    goal = file_goal(args.mesh, up_axis=args.up_axis)
    with Client(args.server, token=args.token) as client:
        start = time.monotonic()
        try:
            response = client.preview(goal, args.rows, args.cols, segments=args.segments)
        except ClientError as e:
            print(f"cad_preview: {e}", file=sys.stderr)
            return 1
        seconds = time.monotonic() - start
    surface = Surface.from_snapshot(response.predicted)
    lo, hi = write_png(args.out, surface)
    correlation = f"{response.correlation:.4f}" if response.HasField("correlation") else \
        f"undefined ({response.correlation_undefined})"
    print(f"{args.mesh} on {args.rows} x {args.cols}: {response.step_count} steps, correlation {correlation}, "
          f"heights {lo:.1f} to {hi:.1f} mm, {seconds:.3f} s{' (cached)' if response.cached else ''}; "
          f"wrote {args.out} ({surface.cols} x {surface.rows} points)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
