#!/usr/bin/env python3
"""check-layout.py — the include graph against the table of allowed arrows, and file lengths.

Every `#include "..."` and `#include <ossa/...>` in format/, common/, runtime/, cooker/, viewer/,
tools/ and tests/runtime/ is resolved to the part it names (a folder: `cooker/import`,
`runtime/anim`, `tools/diff`, ...; the files at the root of cooker/ are the orchestrator,
`cooker/cook`). An include from one part into another must be an arrow of ALLOWED below: no stage
of the cooker includes the orchestrator or a stage that runs after it, the runtime includes nothing
but itself and format/, and nothing includes the cooker but the cooker, its command line, tests
and benches. docs/ARCHITECTURE.md explains the table; change both together.

File lengths: files over --max-lines (650) in those folders are listed. They fail the check only
with --enforce-lines; lines over 120 columns (in those folders and in every C++, GLSL and schema
file of tests/, bench/, examples/ and shaders/) fail only with --enforce-columns. CTest passes both.

Formatting: with --clang-format PROGRAM every C++ file in those folders is checked against
.clang-format (CTest's format_check passes Debian 12's clang-format 14, the version the tree is
formatted with; another version may wrap differently, so the test is added only for 14).

Usage: scripts/check-layout.py [--root DIR] [--enforce-lines] [--enforce-columns] [--graph]
                               [--clang-format PROGRAM]
  --graph prints every arrow between parts (with how many includes make it) and exits 0.
Exit status: 0 clean, 1 a forbidden arrow (or an enforced length), 2 usage error.
"""
import argparse
import os
import re
import subprocess
import sys
from collections import defaultdict

# The cooker's stages in the order data flows through them. A stage may include the model, the
# JSON reader and the stages before it (whose products it reads), never one after it.
COOKER_STAGES = ["cooker/import", "cooker/retarget", "cooker/mesh", "cooker/clip", "cooker/graph", "cooker/texture", "cooker/write"]
RUNTIME_ROOMS = ["runtime/loader", "runtime/anim", "runtime/skinning", "runtime/retarget", "runtime/graph"]


def allowed_table():
    a = defaultdict(set)
    a["format"] = set()
    a["common"] = set()
    # The runtime: rooms in order (a room reads the rooms before it), all over its internal headers.
    a["runtime/internal"] = {"format", "common", "runtime/loader"}  # memory.h: <ossa/loader/allocator.h>
    for i, room in enumerate(RUNTIME_ROOMS):
        a[room] = {"format", "common", "runtime/internal"} | set(RUNTIME_ROOMS[:i])
    runtime_all = set(RUNTIME_ROOMS) | {"runtime/internal"}
    runtime_public = set(RUNTIME_ROOMS)  # through <ossa/...>: see PUBLIC_ONLY below
    # The cooker: JSON reader < model < stages in flow order < orchestrator < command line.
    a["cooker/json"] = {"format", "common"}
    a["cooker/model"] = {"format", "common", "cooker/json"} | runtime_public
    for i, stage in enumerate(COOKER_STAGES):
        a[stage] = {"format", "common", "cooker/json", "cooker/model"} | set(COOKER_STAGES[:i]) | runtime_public
    # Humanoid map files (--map) are read by the retarget stage, the orchestrator and the tools.
    a["cooker/retarget"] |= {"tools/retarget"}
    # The shared cook cache: keys from the model's input log, entries verified by the runtime's
    # loader, written with the writer's atomic files; the orchestrator looks up and stores.
    a["cooker/cache"] = {"format", "common", "cooker/model", "cooker/write"} | runtime_public
    a["cooker/cook"] = ({"format", "common", "cooker/json", "cooker/model", "tools/retarget", "cooker/cache"} |
                        set(COOKER_STAGES) | runtime_public)
    a["cooker/cli"] = a["cooker/cook"] | {"cooker/cook", "tools/cli"}
    # Programs over cooked files: the runtime's public headers, the shared command line.
    a["tools/cli"] = {"format", "common"}
    a["tools/retarget"] = {"format", "common"} | runtime_public
    a["tools/inspect"] = {"format", "common", "tools/cli", "tools/retarget"} | runtime_public
    a["tools/diff"] = {"format", "common", "tools/cli", "tools/inspect"} | runtime_public
    a["viewer"] = {"format", "common", "tools/cli", "tools/retarget"} | runtime_public
    # Runtime suites build in the runtime-only build: the runtime, the format and test support, plus
    # ossa_cook_base (COOK_BASE below), the part of the cooker that needs only FlatBuffers and GLM.
    a["tests/runtime"] = {"format", "common", "tests/support", "cooker/model"} | runtime_all
    a["tests/support"] = {"format", "common", "cooker/model"} | runtime_all
    return a, runtime_all


# ossa_cook_base (cooker/CMakeLists.txt): the writer, root-motion extraction and the plain types
# their headers name. The runtime's suites may include these cooker headers and no others.
COOK_BASE = {"cooker/write/write_ossa.h", "cooker/clip/root_motion.h", "cooker/clip/clip_compress.h",
             "cooker/clip/morph_weights.h", "cooker/mesh/mesh_build.h", "cooker/mesh/morph_build.h"}
TEST_PARTS_ON_BASE = {"tests/runtime", "tests/support"}


# Parts that only their own library may reach by a quoted path into its folders; outside the
# runtime, the runtime is included only through its public <ossa/...> headers.
PUBLIC_ONLY = {"runtime/internal"}

CHECKED_TOPS = ("format", "common", "runtime", "cooker", "viewer", "tools")
LENGTH_TOPS = ("format", "common", "runtime", "cooker", "viewer", "tools")
# Line width (120 columns, what .clang-format holds) is checked in every C++, GLSL and schema file,
# tests, benches and examples included, and in the parts' CMake files.
WIDTH_TOPS = LENGTH_TOPS + ("tests", "bench", "examples", "shaders")
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cc", ".inl")
CODE_EXT = SOURCE_EXT + (".glsl", ".vert", ".frag", ".fbs")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def part_of(rel):
    """The part a repository-relative path belongs to, or None when it is not checked."""
    p = rel.split("/")
    if p[0] in ("format", "common"):
        return p[0]
    if p[0] == "runtime":
        if len(p) >= 4 and p[1] == "include" and p[2] == "ossa":
            return "runtime/" + p[3]
        return "runtime/" + p[1] if len(p) > 2 else "runtime"
    if p[0] == "cooker":
        return "cooker/" + p[1] if len(p) > 2 else "cooker/cook"
    if p[0] == "tools":
        return "tools/" + p[1] if len(p) > 2 else "tools"
    if p[0] == "viewer":
        return "viewer"
    if p[0] == "tests" and len(p) > 2:
        return "tests/" + p[1]
    return None


GENERATED = {"viewer/shader_sources.h"}  # made at build time (viewer/embed_shaders.cmake)


def resolve(root, src_rel, kind, name):
    """Repository-relative path of an include, or None for a system / generated header."""
    if name in GENERATED:
        return name
    if kind == "<":
        if not name.startswith("ossa/"):
            return None
        for base in ("runtime/include", "format/include"):
            if os.path.isfile(os.path.join(root, base, name)):
                return base + "/" + name
        return "format/generated/" + name  # <ossa/version.h>, <ossa/format/ossa_generated.h>
    candidates = [os.path.join(os.path.dirname(src_rel), name), name, "runtime/" + name, "tests/support/" + name]
    for c in candidates:
        c = os.path.normpath(c)
        if os.path.isfile(os.path.join(root, c)):
            return c
    return "?" + name


def walk(root, tops):
    for top in tops:
        for d, dirs, files in os.walk(os.path.join(root, top)):
            dirs.sort()
            for f in sorted(files):
                yield os.path.relpath(os.path.join(d, f), root)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    ap.add_argument("--max-lines", type=int, default=650)
    ap.add_argument("--enforce-lines", action="store_true")
    ap.add_argument("--enforce-columns", action="store_true")
    ap.add_argument("--graph", action="store_true")
    ap.add_argument("--clang-format", metavar="PROGRAM",
                    help="also run PROGRAM --dry-run --Werror over every C++ file (format_check)")
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    allowed, runtime_all = allowed_table()

    arrows = defaultdict(list)  # (from part, to part) -> [file:line]
    unresolved = []
    sources = [r for r in walk(root, CHECKED_TOPS + ("tests/runtime", "tests/support")) if r.endswith(SOURCE_EXT)]
    for rel in sources:
        src_part = part_of(rel)
        if src_part is None:
            continue
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as fh:
            for n, line in enumerate(fh, 1):
                m = INCLUDE_RE.match(line)
                if not m:
                    continue
                target = resolve(root, rel, m.group(1), m.group(2))
                if target is None:
                    continue
                if target.startswith("?"):
                    unresolved.append(f"{rel}:{n}: cannot find \"{target[1:]}\"")
                    continue
                dst_part = "format" if target.startswith("format/") else part_of(target)
                if dst_part is None or dst_part == src_part:
                    continue
                if src_part in TEST_PARTS_ON_BASE and target in COOK_BASE:
                    continue
                arrows[(src_part, dst_part)].append(f"{rel}:{n}")

    if args.graph:
        for (s, d), where in sorted(arrows.items()):
            ok = d in allowed.get(s, set())
            print(f"{s:18} -> {d:18} {len(where):3}  {'' if ok else 'FORBIDDEN'}")
        return 0

    bad = 0
    for (s, d), where in sorted(arrows.items()):
        if s in allowed and d in allowed[s]:
            if d in PUBLIC_ONLY and not s.startswith("runtime/") and s not in ("tests/runtime", "tests/support"):
                pass
            else:
                continue
        bad += 1
        print(f"forbidden arrow {s} -> {d} ({len(where)} include{'s' if len(where) > 1 else ''}):")
        for w in where:
            print(f"    {w}")
    for u in unresolved:
        print(u)
    print(f"include graph: {len(arrows)} arrows between parts, {bad} forbidden, {len(unresolved)} unresolved")

    long_files, wide = [], defaultdict(int)
    for rel in walk(root, WIDTH_TOPS):
        in_part = rel.split("/")[0] in LENGTH_TOPS
        if not (rel.endswith(CODE_EXT) or (in_part and rel.endswith((".txt", ".cmake")))):
            continue
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as fh:
            lines = fh.read().split("\n")
        count = len(lines) - (1 if lines and lines[-1] == "" else 0)
        if in_part and count > args.max_lines:
            long_files.append((count, rel))
        for n, line in enumerate(lines, 1):
            if len(line) > 120:
                wide[rel] += 1
                if args.enforce_columns:
                    print(f"over 120 columns: {rel}:{n} ({len(line)})")
    for count, rel in sorted(long_files, reverse=True):
        print(f"{'over' if args.enforce_lines else 'note: over'} {args.max_lines} lines: {rel} ({count})")
    print(f"file length: {len(long_files)} file(s) over {args.max_lines} lines"
          f"{'' if args.enforce_lines else ' (reported; --enforce-lines fails on them)'}")
    print(f"line length: {sum(wide.values())} line(s) over 120 columns in {len(wide)} file(s)"
          f"{'' if args.enforce_columns else ' (reported; --enforce-columns fails on them)'}")
    unformatted = 0
    if args.clang_format:
        cxx = [os.path.join(root, r) for r in walk(root, WIDTH_TOPS) if r.endswith(SOURCE_EXT)]
        for i in range(0, len(cxx), 64):
            run = subprocess.run([args.clang_format, "--dry-run", "--Werror", "--style=file"] + cxx[i:i + 64],
                                 capture_output=True, text=True)
            if run.returncode != 0:
                unformatted += 1
                print(run.stderr[:4000], end="")
        print(f"clang-format: {len(cxx)} file(s), {'all formatted' if not unformatted else 'some NOT formatted'}"
              f" ({args.clang_format} -i FILE formats one)")
    failed = (bad or unresolved or (args.enforce_lines and long_files) or (args.enforce_columns and wide)
              or unformatted)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
