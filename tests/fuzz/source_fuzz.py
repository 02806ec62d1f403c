#!/usr/bin/env python3
"""source_fuzz.py — a structure-aware fuzzer for ossa-cook (and ossa-view) over real sources.

    python3 tests/fuzz/source_fuzz.py --cook build/bin/ossa-cook --view build/bin/ossa-view \\
        --assets ../shared/assets --seconds 60 --work build/tests/source-fuzz [--seed N]
    python3 tests/fuzz/source_fuzz.py ... --replay tests/fuzz/cook_crashers.json

Mutates real FBX, glTF, GLB, DAE and BVH files from the asset tree the way a careless exporter or
an adversary would — for glTF the JSON (numbers, indices, counts, removed keys), for BVH / DAE the
numbers and lines of the text, for FBX and GLB the bytes (flips, little-endian counts made huge,
truncations) — and cooks them in batches through ossa-cook's isolated workers. What must hold:

  - a batch never crashes: exit status 0 or 1, a report with one record per input;
  - every input either cooks to a file that verifies, or fails with a message naming it; an input
    ended by the isolation (a signal, the memory limit, the time limit) is counted by cause;
  - then the same for .ossa files through the viewer: cooked outputs, bit-flipped, shown headless
    by ossa-view, which must exit 0 (shown) or 1 (refused, naming the file) — never a signal and
    never past its time limit.

A mutated source is not stored (it is a derivative of a third-party asset): each is a recipe, the
asset's path under --assets plus a seed, and the mutation is a pure function of the two. Inputs the
isolation had to end are written to WORK/crashers.json in the --replay format; recipes worth
keeping go into tests/fuzz/cook_crashers.json, which CTest replays (the batch must survive them).
A crash found by hand in a few lines of a format (an .mtl, a Collada accessor) is kept there as an
inline recipe instead: {"input", "files": {name: text}} written as it is.
Prints the figures the closing notes quote. Bounded by --seconds (each batch also by --timeout).
"""
import argparse
import json
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import time

EXTENSIONS = (".fbx", ".gltf", ".glb", ".dae", ".bvh")
MAX_SOURCE_BYTES = 1_300_000  # small sources only: more mutations per second


# ---------------------------------------------------------------------------------------------
# Mutations: (bytes, rng) -> bytes, chosen by the file's format.

def mutate_bytes(data, rng):
    b = bytearray(data)
    if not b:
        return bytes(b)
    kind = rng.randrange(5)
    if kind == 0:  # flip a few bits
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
    elif kind == 1:  # a little-endian count made huge or negative
        if len(b) > 8:
            i = rng.randrange(len(b) - 4)
            b[i:i + 4] = struct.pack("<I", rng.choice([0, 1, 0x7FFFFFFF, 0xFFFFFFFF, 0x10000, 65535, 1 << 24]))
    elif kind == 2:  # truncate
        del b[rng.randrange(len(b)):]
    elif kind == 3:  # duplicate a span
        i = rng.randrange(len(b))
        j = min(len(b), i + rng.randint(1, 4096))
        b[j:j] = b[i:j]
    else:  # random bytes over a span
        i = rng.randrange(len(b))
        for k in range(i, min(len(b), i + rng.randint(1, 64))):
            b[k] = rng.randrange(256)
    return bytes(b)


WEIRD_NUMBERS = [0, -1, 1, 2, 3, 65535, 65536, 2147483647, 4294967295, -2147483648, 1e30, -1e30, 1e-30, 1e300]


def mutate_json_value(root, rng):
    """Picks a random place in the document and changes it."""
    places = []

    def walk(v, parent, key):
        places.append((parent, key, v))
        if isinstance(v, dict):
            for k, c in list(v.items())[:200]:
                walk(c, v, k)
        elif isinstance(v, list):
            for i, c in enumerate(v[:200]):
                walk(c, v, i)

    walk(root, None, None)
    parent, key, v = rng.choice(places[1:] or places)
    if parent is None:
        return root
    kind = rng.randrange(4)
    if kind == 0 and isinstance(parent, dict):
        del parent[key]
    elif isinstance(v, (int, float)) and not isinstance(v, bool):
        parent[key] = rng.choice(WEIRD_NUMBERS + [v * -1, v * 1000, v + 1])
    elif isinstance(v, list) and v and kind == 1:
        parent[key] = v * rng.randint(2, 50) if rng.random() < 0.5 else v[: rng.randrange(len(v))]
    elif isinstance(v, str) and kind == 2:
        parent[key] = rng.choice(["", "../../../../etc/passwd", "/dev/zero", "x" * 100000, v + "\u0000.txt", "%2e%2e/secret.bin"])
    else:
        parent[key] = rng.choice([None, [], {}, "x", True] + WEIRD_NUMBERS)
    return root


def mutate_gltf(data, rng):
    try:
        root = json.loads(data)
    except ValueError:
        return mutate_bytes(data, rng)
    for _ in range(rng.randint(1, 4)):
        root = mutate_json_value(root, rng)
    return json.dumps(root).encode()


def mutate_glb(data, rng):
    if len(data) < 20 or data[:4] != b"glTF" or rng.random() < 0.3:
        return mutate_bytes(data, rng)
    length = struct.unpack_from("<I", data, 12)[0]
    chunk = data[20:20 + length]
    try:
        root = json.loads(chunk)
    except ValueError:
        return mutate_bytes(data, rng)
    for _ in range(rng.randint(1, 4)):
        root = mutate_json_value(root, rng)
    text = json.dumps(root).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + ((length + 3) & ~3):]
    return struct.pack("<III", 0x46546C67, 2, 20 + len(text) + len(rest)) + struct.pack("<II", len(text), 0x4E4F534A) + text + rest


NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def mutate_text(data, rng):
    """BVH / DAE / ASCII: numbers replaced, lines deleted or duplicated, truncation."""
    kind = rng.randrange(4)
    if kind == 0:
        matches = list(NUMBER.finditer(data[:2_000_000]))
        if matches:
            out = bytearray(data)
            for m in sorted(rng.sample(matches, min(len(matches), rng.randint(1, 6))), key=lambda m: -m.start()):
                out[m.start():m.end()] = str(rng.choice(WEIRD_NUMBERS)).encode()
            return bytes(out)
    lines = data.split(b"\n")
    if kind == 1 and len(lines) > 2:
        del lines[rng.randrange(len(lines))]
        return b"\n".join(lines)
    if kind == 2 and len(lines) > 2:
        i = rng.randrange(len(lines))
        lines[i:i] = [lines[i]] * rng.randint(1, 200)
        return b"\n".join(lines)
    return mutate_bytes(data, rng)


def mutate(path, data, seed):
    rng = random.Random(seed)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".gltf":
        return mutate_gltf(data, rng)
    if ext == ".glb":
        return mutate_glb(data, rng)
    if ext in (".bvh", ".dae"):
        return mutate_text(data, rng)
    return mutate_bytes(data, rng)


# ---------------------------------------------------------------------------------------------

def sources(assets):
    out = []
    for root, _, files in os.walk(assets):
        for name in sorted(files):
            path = os.path.join(root, name)
            if name.lower().endswith(EXTENSIONS) and os.path.getsize(path) <= MAX_SOURCE_BYTES:
                out.append(os.path.relpath(path, assets))
    return sorted(out)


def cause_of(error):
    for needle, cause in (("worker killed by signal", "signal"), ("exceeded the memory limit", "memory limit"),
                          ("exceeded the time limit", "time limit"), ("unreadable record", "garbled record")):
        if needle in error:
            if cause == "signal":
                m = re.search(r"signal (\d+)", error)
                return "signal " + (m.group(1) if m else "?")
            return cause
    return None


def recipe_key(recipe):
    """(asset, seed) of a mutation recipe, or (input name, None) of an inline one."""
    if isinstance(recipe, dict):
        return recipe["input"], None
    return recipe


def cook_batch(args, recipes, batch_dir, stats):
    """Writes the recipes' sources, cooks them in one batch; returns crashers.

    A recipe is (asset, seed): a mutation of a file under --assets; or a dict {"input", "files"}:
    small files written as they are (sources authored for the corpus, no third-party bytes)."""
    shutil.rmtree(batch_dir, ignore_errors=True)
    src, out = os.path.join(batch_dir, "src"), os.path.join(batch_dir, "out")
    os.makedirs(src)
    names = []
    for k, recipe in enumerate(recipes):
        folder = os.path.join(src, str(k))  # each in a folder of its own (same stems, sidecars)
        os.makedirs(folder)
        if isinstance(recipe, dict):
            for file_name, text in recipe["files"].items():
                with open(os.path.join(folder, file_name), "w") as f:
                    f.write(text)
            names.append(os.path.join(folder, recipe["input"]))
            continue
        rel, seed = recipe
        with open(os.path.join(args.assets, rel), "rb") as f:
            data = f.read()
        name = os.path.join(folder, os.path.basename(rel))
        with open(name, "wb") as f:
            f.write(mutate(rel, data, seed))
        names.append(name)
    report = os.path.join(batch_dir, "report.json")
    cmd = [args.cook, *names, "-o", out, "--root", src, "--jobs", "2", "-q", "--timeout", str(args.timeout),
           "--max-memory", args.max_memory, "--report", report]
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=args.timeout * len(names) + 60)
    stats["batches"] += 1
    stats["sources"] += len(names)
    if proc.returncode not in (0, 1) or not os.path.exists(report):
        stats["batch_crashes"] += 1
        print(f"source_fuzz: BATCH CRASHED (exit {proc.returncode}): {proc.stderr[-2000:].decode(errors='replace')}")
        return [{"asset": recipe_key(r)[0], "seed": recipe_key(r)[1], "cause": f"batch exit {proc.returncode}"}
                for r in recipes]
    with open(report) as f:
        doc = json.load(f)
    crashers = []
    if len(doc["records"]) != len(names):
        stats["batch_crashes"] += 1
        print(f"source_fuzz: report has {len(doc['records'])} records for {len(names)} inputs")
    for k, rec in enumerate(doc["records"]):
        if rec["status"] == "ok":
            stats["cooked"] += 1
            if len(stats["outputs"]) < 100:  # kept for the viewer round (the batch folder is reused)
                pool = os.path.join(args.work, "pool")
                os.makedirs(pool, exist_ok=True)
                kept = os.path.join(pool, f"{stats['cooked']}.ossa")
                shutil.copyfile(rec["output"], kept)
                stats["outputs"].append(kept)
            continue
        stats["failed"] += 1
        cause = cause_of(rec.get("error", ""))
        if cause:
            stats["isolated"][cause] = stats["isolated"].get(cause, 0) + 1
            crashers.append({"asset": recipe_key(recipes[k])[0], "seed": recipe_key(recipes[k])[1], "cause": cause})
        elif os.path.basename(recipe_key(recipes[k])[0]).split(".")[0] not in rec.get("error", ""):
            stats["unnamed_errors"] += 1
            print(f"source_fuzz: an error does not name its input: {rec.get('error', '')[:300]}")
    return crashers


def flip(data, rng):
    b = bytearray(data)
    for _ in range(rng.randint(1, 16)):
        i = rng.randrange(len(b))
        b[i] ^= 1 << rng.randrange(8)
    return bytes(b)


def view_round(args, outputs, work, rng, stats, deadline):
    """Bit-flipped cooked files through ossa-view headless, one process each."""
    folder = os.path.join(work, "view")
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    while time.time() < deadline and outputs and (args.view_files == 0 or stats["view_files"] < args.view_files):
        path = rng.choice(outputs)
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            continue
        seed = rng.randrange(1 << 30)
        mutated = os.path.join(folder, f"m{seed}.ossa")
        with open(mutated, "wb") as f:
            f.write(flip(data, random.Random(seed)) if data else data)
        try:
            proc = subprocess.run([args.view, mutated, "--size", "64x64", "--frames", "2", "-q"], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.PIPE, timeout=30)
            code = proc.returncode
        except subprocess.TimeoutExpired:
            code = "timeout"
        stats["view_files"] += 1
        if code == 0:
            stats["view_shown"] += 1
        elif code in (1, 2) and os.path.basename(mutated).encode() in proc.stderr:
            stats["view_refused"] += 1
        else:
            stats["view_crashes"] += 1
            print(f"source_fuzz: ossa-view on a mutation of {path} (seed {seed}): exit {code}: "
                  f"{proc.stderr[-500:].decode(errors='replace') if code != 'timeout' else ''}")
        os.remove(mutated)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cook", required=True)
    ap.add_argument("--view")
    ap.add_argument("--assets", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--seconds", type=float, default=60, help="stop starting batches after this long")
    ap.add_argument("--batches", type=int, default=0, help="stop after this many batches (0: no limit); "
                    "with --seed, what CI runs is the same every time")
    ap.add_argument("--view-seconds", type=float, default=20)
    ap.add_argument("--view-files", type=int, default=0, help="stop the viewer round after this many files (0: no limit)")
    ap.add_argument("--seed", type=int, default=int(time.time()))
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--timeout", type=int, default=10)
    ap.add_argument("--max-memory", default="1536M")
    ap.add_argument("--replay", help="cook these recipes (a crashers.json) instead of fuzzing")
    args = ap.parse_args()
    if not os.path.isdir(args.assets) and not args.replay:
        print(f"source_fuzz: no asset tree at {args.assets}: nothing to fuzz")
        return 0
    os.makedirs(args.work, exist_ok=True)
    stats = {"batches": 0, "sources": 0, "cooked": 0, "failed": 0, "isolated": {}, "batch_crashes": 0,
             "unnamed_errors": 0, "outputs": [], "view_files": 0, "view_shown": 0, "view_refused": 0, "view_crashes": 0}
    crashers = []
    rng = random.Random(args.seed)
    if args.replay:
        with open(args.replay) as f:
            listed = json.load(f)["recipes"]
        # Inline recipes always; mutation recipes where their asset is present.
        recipes = [r if "files" in r else (r["asset"], r["seed"]) for r in listed]
        recipes = [r for r in recipes if isinstance(r, dict) or os.path.exists(os.path.join(args.assets, r[0]))]
        if recipes:
            crashers += cook_batch(args, recipes, os.path.join(args.work, "replay"), stats)
    else:
        pool = sources(args.assets)
        deadline = time.time() + args.seconds
        while time.time() < deadline and (args.batches == 0 or stats["batches"] < args.batches):
            recipes = [(rng.choice(pool), rng.randrange(1 << 30)) for _ in range(args.batch)]
            crashers += cook_batch(args, recipes, os.path.join(args.work, "batch"), stats)
        if args.view:
            view_round(args, stats["outputs"], args.work, rng, stats, time.time() + args.view_seconds)
    with open(os.path.join(args.work, "crashers.json"), "w") as f:
        json.dump({"recipes": crashers}, f, indent=1)
    print(f"source_fuzz: seed {args.seed}: {stats['sources']} sources mutated, {stats['batches']} batches, "
          f"{stats['batch_crashes']} batch crashes, {stats['cooked']} cooked, {stats['failed']} failed "
          f"({stats['unnamed_errors']} without naming the input), ended by isolation: "
          f"{json.dumps(stats['isolated'], sort_keys=True)}")
    if args.view:
        print(f"source_fuzz: ossa-view: {stats['view_files']} mutated .ossa files, {stats['view_shown']} shown, "
              f"{stats['view_refused']} refused by name, {stats['view_crashes']} crashes or hangs")
    ok = stats["batch_crashes"] == 0 and stats["unnamed_errors"] == 0 and stats["view_crashes"] == 0
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
