#!/usr/bin/env python3
"""bench_cook.py — what ossa-cook does to a whole asset tree as a build step, measured.

    python3 bench/bench_cook.py [--cook build/bin/ossa-cook] [--assets ../shared/assets] [--jobs 1 2]

Copies the tree to a private folder (it edits a texture), then for each --jobs value prints:
  - a full cook (--force): wall time, inputs per second, source MB per second;
  - an all-up-to-date re-run: wall time and its share of the full cook (target: under 5 %);
  - a re-run after editing one texture: wall time and how many outputs were re-cooked (target: 1).
Then the shared cook cache (--cache; docs/SCALE.md), one row per back end (a folder; HTTP through an
nginx with WebDAV that the script starts on loopback, when nginx is installed) and tree (the asset
tree; --many generated small BVH sources, to show the cache's own cost per file):
  - a full cook of the tree without a cache (the reference);
  - "machine A": a clone cooked into an empty cache: wall time, bytes stored;
  - "machine B": a second clone in another folder, empty output, warm cache: wall time and its
    share of the full cook (target: at most 10 %), cooks run, hits, bytes fetched; its outputs must
    equal the full cook's bytes.
Counts come from each run's --report (docs/JSON.md), times from the wall clock around the process,
best of --repeat runs (cache rows: one run each, as a cold cache exists once). Name the CPU when
quoting (the script prints /proc/cpuinfo's model name).

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


def start_nginx(work):
    """nginx serving a WebDAV folder on a free loopback port, everything under work/nginx; returns
    (url, stop) or (None, why)."""
    import socket
    exe = shutil.which("nginx") or next((p for p in ("/usr/sbin/nginx",) if os.path.exists(p)), None)
    if exe is None:
        return None, "nginx not installed"
    d = os.path.join(work, "nginx")
    os.makedirs(os.path.join(d, "data"), exist_ok=True)
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    user = ""
    if os.geteuid() == 0:
        import grp
        import pwd
        user = f"user {pwd.getpwuid(os.geteuid()).pw_name} {grp.getgrgid(os.getegid()).gr_name};\n"
    conf = os.path.join(d, "nginx.conf")
    with open(conf, "w") as f:
        f.write(f"""{user}worker_processes 2;
pid {d}/nginx.pid;
error_log {d}/error.log;
events {{ worker_connections 1024; }}
http {{
  access_log off;
  client_body_temp_path {d}/body;
  server {{
    listen 127.0.0.1:{port};
    root {d}/data;
    client_max_body_size 0;
    location / {{ dav_methods PUT; create_full_put_path on; dav_access user:rw; }}
  }}
}}
""")
    proc = subprocess.run([exe, "-p", d, "-e", f"{d}/error.log", "-c", conf], capture_output=True, text=True)
    if proc.returncode != 0:
        return None, "nginx did not start: " + proc.stderr.strip()
    for _ in range(100):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            time.sleep(0.05)

    def stop():
        with open(os.path.join(d, "nginx.pid")) as f:
            os.kill(int(f.read()), 15)
    return f"http://127.0.0.1:{port}", stop


def make_many(tree, count):
    """`count` small BVH sources (3 joints, 30 frames), each with bytes of its own, 100 to a folder."""
    for i in range(count):
        d = os.path.join(tree, f"d{i // 100:03d}")
        os.makedirs(d, exist_ok=True)
        frames = "\n".join(" ".join(f"{(i * 7 + f * 3 + c) % 90 * 0.5:.2f}" for c in range(12)) for f in range(30))
        with open(os.path.join(d, f"clip{i:05d}.bvh"), "w") as f:
            f.write(f"""HIERARCHY
ROOT Hips
{{
  OFFSET 0.00 0.00 0.00
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {{
    OFFSET 0.00 10.00 0.00
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Head
    {{
      OFFSET 0.00 10.00 0.00
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {{
        OFFSET 0.00 5.00 0.00
      }}
    }}
  }}
}}
MOTION
Frames: 30
Frame Time: 0.033333
{frames}
""")


def snapshot(out):
    files = {}
    for root, _, names in os.walk(out):
        for name in names:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                files[os.path.relpath(path, out)] = f.read()
    return files


def cache_rows(cook, work, label, source, jobs, caches, report):
    """The shared-cache rows of one tree: a reference full cook, then machine A (cold) and machine
    B (warm) per back end."""
    clone_a, clone_b = os.path.join(work, label + "-A"), os.path.join(work, label + "-B")
    for clone in (clone_a, clone_b):
        shutil.copytree(source, clone)
    full_s, full_doc = run(cook, clone_b, os.path.join(work, label + "-full"), jobs, ["--force"], report,
                           batches(clone_b))
    reference = snapshot(os.path.join(work, label + "-full"))
    for name, location in caches:
        out_a, out_b = os.path.join(work, f"{label}-{name}-outA"), os.path.join(work, f"{label}-{name}-outB")
        a_s, a_doc = run(cook, clone_a, out_a, jobs, ["--cache", location], report, batches(clone_a))
        b_s, b_doc = run(cook, clone_b, out_b, jobs, ["--cache", location], report, batches(clone_b))
        stored = sum(r.get("cache_bytes_stored", 0) for r in a_doc["records"]) / 1e6
        fetched = sum(r.get("cache_bytes_fetched", 0) for r in b_doc["records"]) / 1e6
        hits = sum(1 for r in b_doc["records"] if r.get("cache_hit"))
        cooked = sum(1 for r in b_doc["records"] if r["status"] == "ok" and not r.get("cache_hit")
                     and not r.get("up_to_date"))
        same = "yes" if snapshot(out_b) == reference else "NO"
        print(f"{label:>8} {name:>6} {full_doc['inputs']:>6} {full_s:>7.2f} {a_s:>7.2f} {stored:>9.1f} {b_s:>7.2f} "
              f"{100 * b_s / full_s:>6.1f}% {cooked:>5} {hits:>5} {fetched:>10.1f} "
              f"{1e3 * b_s / full_doc['inputs']:>8.2f} {same:>9}")


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
    ap.add_argument("--many", type=int, default=2000, help="generated sources of the many-file cache row (0: none)")
    ap.add_argument("--only-cache", action="store_true", help="print the shared-cache rows only")
    ap.add_argument("--no-cache", action="store_true", help="leave the shared-cache rows out")
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
        if args.only_cache:
            args.jobs = []
        if args.jobs:
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
        if args.jobs and texture:
            print(f"edited texture: {os.path.relpath(texture, tree)}")
        if args.no_cache:
            return
        jobs = max(args.jobs) if args.jobs else 2
        caches = [("folder", os.path.join(work, "cache-folder"))]
        url, stop = start_nginx(work)
        if url:
            caches.append(("http", url))
        else:
            print(f"(no HTTP rows: {stop})")
        print(f"\nshared cook cache, --jobs {jobs}: machine A cooks a clone into an empty cache, machine B a second "
              f"clone (empty output) from it")
        print(f"{'tree':>8} {'cache':>6} {'inputs':>6} {'full s':>7} {'A s':>7} {'stored MB':>9} {'B s':>7} "
              f"{'B/full':>7} {'cooks':>5} {'hits':>5} {'fetched MB':>10} {'B ms/in':>8} {'identical':>9}")
        try:
            cache_rows(args.cook, work, "assets", args.assets, jobs, caches, report)
            if args.many > 0:
                many = os.path.join(work, "many-src")
                make_many(many, args.many)
                caches = [(n, loc + "-many" if n == "folder" else loc) for n, loc in caches]
                cache_rows(args.cook, work, "many", many, jobs, caches, report)
        finally:
            if url:
                stop()


if __name__ == "__main__":
    main()
