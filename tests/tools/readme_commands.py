#!/usr/bin/env python3
"""readme_commands.py — every command the README shows runs as written.

Extracts the fenced ```sh blocks of README.md and runs their commands in order, in a scratch folder
that looks like a checkout after a build (assets/ and build/bin/ are links to the real ones), each
through bash, each required to exit 0: the cooks, ossa-inspect, ossa-diff, and the viewer where the
command renders headless (--screenshot / --frames, under the xvfb-run it names). Not run: the two
entry points (scripts/demo.sh, scripts/test.sh, which install packages and build), and viewer
commands that open a window; for those, every file they name must exist once the cooks above them
have run, so a renamed sample or output still fails here.

Usage: readme_commands.py --readme README.md --bin build/bin --assets assets --work DIR
Exit status: 0 every command ran and passed, 1 one failed (named, with its output), 2 usage.
"""
import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys


def sh_blocks(text):
    """The commands of every ```sh block, backslash continuations joined, comments dropped."""
    commands = []
    for block in re.findall(r"^```sh\n(.*?)^```", text, re.S | re.M):
        pending = ""
        for line in block.split("\n"):
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            line = (pending + line).strip()
            pending = ""
            if line and not line.startswith("#"):
                commands.append(line)
    return commands


def words(command):
    return shlex.split(command, comments=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--readme", required=True)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--assets", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    with open(args.readme, encoding="utf-8") as fh:
        commands = sh_blocks(fh.read())
    if not commands:
        print(f"{args.readme}: no ```sh commands found")
        return 1

    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(os.path.join(args.work, "build"))
    os.symlink(os.path.abspath(args.assets), os.path.join(args.work, "assets"))
    os.symlink(os.path.abspath(args.bin), os.path.join(args.work, "build", "bin"))

    ran = skipped = 0
    for command in commands:
        w = words(command)
        if w and w[0] in ("scripts/demo.sh", "scripts/test.sh"):
            print(f"skipped (entry point): {command}")
            skipped += 1
            continue
        viewer = "build/bin/ossa-view" in w
        headless = any(flag in w for flag in ("--screenshot", "--frames"))
        if viewer and not headless:
            # A window: not opened here, but every file it names must be there.
            after = w[w.index("build/bin/ossa-view") + 1:]
            missing = [a for a in after if a.endswith(".ossa") and not os.path.exists(os.path.join(args.work, a))]
            if missing:
                print(f"FAILED: {command}\n  names files no command above made: {', '.join(missing)}")
                return 1
            print(f"checked (opens a window, files exist): {command}")
            skipped += 1
            continue
        result = subprocess.run(["bash", "-c", command], cwd=args.work, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, errors="replace", timeout=600)
        if result.returncode != 0:
            print(f"FAILED (exit {result.returncode}): {command}\n{result.stdout[-4000:]}")
            return 1
        print(f"ok: {command}")
        ran += 1
    print(f"{ran} README commands ran and passed, {skipped} not run ({args.readme})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
