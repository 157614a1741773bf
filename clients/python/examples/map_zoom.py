#!/usr/bin/env python3
"""Map zoom: ask hapticjam-server for successive regions of a DEM, as a map
viewer zooming in and back out would, and print each region's correlation
and answer time. The DEM is a map the server was started with (--map NAME)
or a file sent as bytes (--dem FILE). Returning to a region is answered from
the server's cache.

    PYTHONPATH=build/clients/python:clients/python python3 clients/python/examples/map_zoom.py \
        --server 127.0.0.1:50051 --dem ../shared/data/dem/volcano_maunga_whau.csv
"""

import argparse
import sys
import time

from hapticjam_client import Client, ClientError, file_goal, map_goal

# Zoom into the centre in three steps, then back out to the first two.
REGIONS = [
    (0.0, 0.0, 1.0, 1.0),
    (0.125, 0.125, 0.875, 0.875),
    (0.25, 0.25, 0.75, 0.75),
    (0.375, 0.375, 0.625, 0.625),
    (0.25, 0.25, 0.75, 0.75),
    (0.0, 0.0, 1.0, 1.0),
]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--map", help="a map the server holds (hapticjam-server --map NAME=FILE)")
    source.add_argument("--dem", help="a DEM file to send (CSV, PNG, TIFF)")
    p.add_argument("--server", required=True, help="HOST:PORT of hapticjam-server")
    p.add_argument("--token", default=None)
    p.add_argument("--rows", type=int, default=3)
    p.add_argument("--cols", type=int, default=4)
    args = p.parse_args()

    with Client(args.server, token=args.token) as client:
        print(f"{'region (fractions)':<28} {'correlation':>11} {'seconds':>8}  cached")
        for region in REGIONS:
            goal = map_goal(args.map, region) if args.map else file_goal(args.dem, region)
            start = time.monotonic()
            try:
                r = client.preview(goal, args.rows, args.cols)
            except ClientError as e:
                print(f"map_zoom: {e}", file=sys.stderr)
                return 1
            seconds = time.monotonic() - start
            corr = f"{r.correlation:.4f}" if r.HasField("correlation") else "undefined"
            print(f"{','.join(f'{v:g}' for v in region):<28} {corr:>11} {seconds:8.3f}  {'yes' if r.cached else 'no'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
