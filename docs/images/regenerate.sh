#!/bin/sh
# Redraws the pictures in docs/images with the commands that make them, each beside the record that command wrote
# (comparison.json: sid demo's metrics.json; simulate_*.json: the run's run.json). tests/test_doc_images.py checks
# them against what the commands draw today. About a minute; run from anywhere, with SID set to another way of
# calling sid if needed (SID="python -m sid"). simulate_sweep.png is the chart of the 28-minute sweep in
# docs/simulate.md (`sid simulate --sweep all --seeds 15 --workers 1`, 5 December 2026) and is not redrawn here.
set -eu
SID=${SID:-sid}
cd "$(dirname "$0")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
$SID demo --out "$tmp/demo"
cp "$tmp/demo/comparison.png" comparison.png
cp "$tmp/demo/metrics.json" comparison.json
$SID simulate paper --still 3 --out "$tmp/paper"
cp "$tmp/paper/run.png" simulate_paper.png
cp "$tmp/paper/run.json" simulate_paper.json
$SID simulate paper --no-social --still 9 --out "$tmp/without"
cp "$tmp/without/run.png" simulate_paper_without.png
cp "$tmp/without/run.json" simulate_paper_without.json
