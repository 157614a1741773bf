#!/usr/bin/env python3
"""Dataset compare: upload a dataset folder of measurement sessions to
hapticjam-server and compare the model with it there (CalibrationService
Compare), printing the server's progress, the RMSE per session and
writing summary.json and, with --report, the self-contained report.html
(what `hapticjam compare` writes).

    PYTHONPATH=build/clients/python:clients/python python3 clients/python/examples/dataset_compare.py \
        --server 127.0.0.1:50051 ../shared/data/sessions/demo-baseline --out summary.json --report report.html
"""

import argparse
import json
import sys

from hapticjam_client import Client, ClientError, dataset_upload


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dataset", help="a folder of session folders")
    p.add_argument("--server", required=True, help="HOST:PORT")
    p.add_argument("--token", default=None)
    p.add_argument("--params", default=None, help="a hapticjam.params/1 file (e.g. from fit)")
    p.add_argument("--out", default=None, help="write the returned summary.json here")
    p.add_argument("--report", default=None, help="write the returned report.html (heat maps embedded) here")
    args = p.parse_args()
    params = open(args.params).read() if args.params else ""

    def show(progress):
        print(f"\r{progress.stage}: {progress.done}/{progress.total} {progress.detail}", end="", file=sys.stderr)

    with Client(args.server, token=args.token) as client:
        try:
            result = client.compare(dataset_upload(args.dataset), params_json=params, on_progress=show)
        except ClientError as e:
            print(f"\n{e}", file=sys.stderr)
            return 1
    print(file=sys.stderr)
    summary = json.loads(result.summary_json)
    for session in summary["sessions"]:
        errors = [c["rmse_mm"] for c in session["captures"]]
        print(f"{session['name']:20s} {len(errors):3d} captures, worst RMSE {max(errors):.3f} mm")
    print(f"all: RMSE {result.rmse_mm:.3f} mm over {result.samples} samples (noise floor {result.noise_floor_mm:.3f} mm)")
    if args.out:
        with open(args.out, "w") as f:
            f.write(result.summary_json + "\n")
    if args.report:
        with open(args.report, "w") as f:
            f.write(result.report_html)
    return 0


if __name__ == "__main__":
    sys.exit(main())
