#!/usr/bin/env python3
"""bench_cook.py — what ossa-cook does to a whole asset tree as a build step, measured.

    python3 bench/bench_cook.py [--cook build/bin/ossa-cook] [--assets ../shared/assets] [--jobs 1 2]

Copies the tree to a private folder (it edits a texture), then for each --jobs value prints:
  - a full cook (--force): wall time, inputs per second, source MB per second;
  - an all-up-to-date re-run: wall time and its share of the full cook (target: under 5 %);
  - a re-run after editing one texture: wall time and how many outputs were re-cooked (target: 1).
Counts come from each run's --report (docs/JSON.md), times from the wall clock around the process,
best of --repeat runs. Name the CPU when quoting (the script prints /proc/cpuinfo's model name).

A script, not a Google Benchmark binary: what is measured is the ossa-cook process over files,
the way a build system runs it, including process start and every file read.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


SOURCE_EXTENSIONS = (".fbx", ".gltf", ".glb", ".dae", ".bvh", ".obj")


def batches(tree):
    """The tree's inputs split into batches in which no two share a folder and output stem (the
    shared tree has Pab/skeleton.fbx and Pab/skeleton.dae, which one batch would refuse)."""
    inputs = []
    for root, _, files in os.walk(tree):
        for name in sorted(files):
            low = name.lower()
            if low.endswith(SOURCE_EXTENSIONS) or low.endswith(".graph.json"):
                inputs.append(os.path.join(root, name))
    out = []
    for path in sorted(inputs):
        name = os.path.basename(path)
        stem = name[: -len(".graph.json")] if name.lower().endswith(".graph.json") else os.path.splitext(name)[0]
        key = (os.path.dirname(path), stem)
        for batch in out:
            if key not in batch:
                batch[key] = path
                break
        else:
            out.append({key: path})
    return [sorted(b.values()) for b in out]


def run(cook, tree, out, jobs, extra, report, groups):
    """One ossa-cook process per batch (output folders out/0, out/1, ...); total wall time and
    the merged report."""
    seconds, merged = 0.0, {"inputs": 0, "failed": 0, "records": []}
    for k, inputs in enumerate(groups):
        cmd = [cook, *inputs, "-o", os.path.join(out, str(k)), "--root", str(tree), "--jobs", str(jobs), "-q",
               "--report", str(report)] + extra
        start = time.perf_counter()
        proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        seconds += time.perf_counter() - start
        if proc.returncode not in (0, 1):
            sys.exit(f"bench_cook: {' '.join(cmd)} exited {proc.returncode}: {proc.stderr}")
        with open(report) as f:
            doc = json.load(f)
        merged["inputs"] += doc["inputs"]
        merged["failed"] += doc["failed"]
        merged["records"] += doc["records"]
    return seconds, merged


def pick_texture(doc, tree):
    """A texture file some output read (the first in path order), for the one-edit re-run."""
    for rec in doc["records"]:
        for inp in rec.get("inputs_read", []):
            if inp.get("absent"):
                continue
            if inp["path"].lower().endswith((".png", ".jpg", ".jpeg")):
                return os.path.normpath(os.path.join(os.path.dirname(rec["input"]), inp["path"]))
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cook", default="build/bin/ossa-cook")
    ap.add_argument("--assets", default="../shared/assets")
    ap.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeat", type=int, default=3, help="best of N for each timing (default 3)")
    args = ap.parse_args()
    if not os.path.isdir(args.assets):
        sys.exit(f"bench_cook: no asset tree at {args.assets}")

    print(f"CPU: {cpu_model()} ({os.cpu_count()} cores)")
    with tempfile.TemporaryDirectory(prefix="ossa-bench-cook-") as work:
        tree = os.path.join(work, "assets")
        shutil.copytree(args.assets, tree)
        for root, dirs, files in os.walk(tree):
            for name in dirs + files:
                os.chmod(os.path.join(root, name), 0o755 if name in dirs else 0o644)
        report = os.path.join(work, "report.json")
        groups = batches(tree)
        print(f"{'jobs':>4} {'inputs':>6} {'failed':>6} {'source MB':>9} {'full s':>7} {'files/s':>7} {'MB/s':>6} "
              f"{'fresh s':>7} {'fresh %':>7} {'1 tex s':>7} {'re-cooked':>9}")
        for jobs in args.jobs:
            out = os.path.join(work, f"out-{jobs}")
            full = []
            for _ in range(args.repeat):
                seconds, doc = run(args.cook, tree, out, jobs, ["--force"], report, groups)
                full.append(seconds)
            inputs, failed = doc["inputs"], doc["failed"]
            mb = sum(r.get("source_bytes", 0) for r in doc["records"]) / 1e6
            fresh = []
            for _ in range(args.repeat):
                seconds, fdoc = run(args.cook, tree, out, jobs, [], report, groups)
                fresh.append(seconds)
                stale = [r["input"] for r in fdoc["records"] if r["status"] == "ok" and not r["up_to_date"]]
                if stale:
                    sys.exit(f"bench_cook: an unchanged tree re-cooked {stale}")
            texture = pick_texture(doc, tree)
            edit_s, recooked = float("nan"), "-"
            if texture:
                with open(texture, "ab") as f:
                    f.write(b"\0")
                edit_s, edoc = run(args.cook, tree, out, jobs, [], report, groups)
                recooked = str(sum(1 for r in edoc["records"] if r["status"] == "ok" and not r["up_to_date"]))
            best_full, best_fresh = min(full), min(fresh)
            print(f"{jobs:>4} {inputs:>6} {failed:>6} {mb:>9.1f} {best_full:>7.2f} {inputs / best_full:>7.1f} "
                  f"{mb / best_full:>6.1f} {best_fresh:>7.3f} {100 * best_fresh / best_full:>6.1f}% {edit_s:>7.2f} "
                  f"{recooked:>9}")
        if texture:
            print(f"edited texture: {os.path.relpath(texture, tree)}")


if __name__ == "__main__":
    main()
