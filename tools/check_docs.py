#!/usr/bin/env python3
"""Runs the ```console blocks of the documentation and compares their output.

    tools/check_docs.py --skybake build/bin/skybake README.md docs/baking.md ...

CTest runs it once per file as docs.NAME (label docs; `make test` runs it).

A block
-------
In a ```console block, a line starting with `$ ` is a command (a line ending
in a backslash continues on the next); the lines up to the next command are
its expected output, stdout and stderr together. Every file runs in a fresh
temporary folder, its blocks in order, so a block can use what an earlier
block of the same file wrote. Commands run under bash with the build's
`skybake` first on PATH; stdin is /dev/null, so no progress bars appear.
A command whose expected output has a line starting with `skybake: error:`
must fail (exit code not 0); any other must succeed. A command with no
expected output must print nothing.

Masks
-----
Both sides are masked before they are compared:
- a time: a number followed by s, ms, us, µs, min or h ("0.57 s", "12ms");
- a rate: a number followed by a unit per second ("27.5 Mrays/s", "71428 texels/s", "42956/s");
- a JSON value whose key ends in "seconds" or "per_second";
- a thread count ("2 threads", "\"threads\": 2");
- the temporary folder's path (written <tmp>).
Beyond that the expected output may say what it does not pin down:
- a line that is exactly `...` matches any number of lines, none included;
- `...` inside a line matches any text on that line.
Everything else (counts, results, messages) must match exactly.

Markers
-------
HTML comments on the lines just before a block's opening fence (blank lines
between are allowed) change how it runs:
- `<!-- docs-test: skip: REASON -->`: the block does not run (a window, a GPU,
  minutes of work). Keep these few; the reason is printed.
- `<!-- docs-test: no-gpu -->`: the output shown is that of a CUDA build on a
  machine without a CUDA device (errors about the device, Mesa's llvmpipe as
  the OpenGL); the block runs only where `skybake --version` says
  `with CUDA, no device found`.
- `<!-- docs-test: setup: COMMAND -->`: COMMAND runs before the block, in the
  same folder (it must succeed, else the block fails without running; its
  output is not compared). $SKYBAKE_SOURCE_DIR is the source tree, for files
  the docs name by their path in it.

Environment
-----------
CTest passes the tests' environment (SKYBAKE_TEST_ENVIRONMENT in CMake);
run by hand, SKYBAKE_CACHE_DIR defaults to `off` all the same, so that the
multiple-scattering tables are computed (and said to be) every time.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^```(\w*)\s*$")
MARKER = re.compile(r"^<!--\s*docs-test:\s*(skip|no-gpu|setup)\s*(?::\s*(.*?))?\s*-->\s*$")

TIME = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)? ?(?:s|ms|us|µs|min|h)\b(?!/)")
RATE = re.compile(r"(?<![\w.])\d+(?:\.\d+)?(?:[eE][-+]?\d+)? ?[A-Za-z]*/s\b")
JSON_TIME = re.compile(r'("\w*(?:seconds|per_second)"\s*:\s*)[-+0-9.eE]+')
THREADS = re.compile(r"\b\d+ threads?\b")
JSON_THREADS = re.compile(r'("threads"\s*:\s*)\d+')


class Block:
    def __init__(self, path, line, lines, markers):
        self.path = path
        self.line = line  # 1-based line of the opening fence
        self.markers = markers  # [(kind, argument)]
        self.commands = []  # [(line, command, [expected lines])]
        current = None
        pending = None
        for i, text in enumerate(lines):
            n = line + 1 + i
            if pending is not None:  # a continued command
                pending[1] += "\n" + text
                if not text.endswith("\\"):
                    current = [pending[0], pending[1], []]
                    self.commands.append(current)
                    pending = None
                continue
            if text.startswith("$ "):
                cmd = text[2:]
                if cmd.endswith("\\"):
                    pending = [n, cmd]
                else:
                    current = [n, cmd, []]
                    self.commands.append(current)
            elif current is not None:
                current[2].append(text)
            elif text.strip():
                raise SystemExit(f"{path}:{n}: console block output before any `$ ` command")
        if pending is not None:
            raise SystemExit(f"{path}:{pending[0]}: the block ends inside a continued command")
        for c in self.commands:  # the blank lines between commands are not output
            while c[2] and not c[2][-1].strip():
                c[2].pop()


def parse(path):
    with open(path, encoding="utf-8") as f:
        text = f.read().split("\n")
    blocks = []
    i = 0
    while i < len(text):
        m = FENCE.match(text[i])
        if not m:
            i += 1
            continue
        start = i
        j = i + 1
        while j < len(text) and not text[j].startswith("```"):
            j += 1
        if m.group(1) == "console":
            markers = []
            k = start - 1
            while k >= 0 and (not text[k].strip() or MARKER.match(text[k])):
                mk = MARKER.match(text[k])
                if mk:
                    kind, arg = mk.group(1), (mk.group(2) or "")
                    if kind in ("skip", "setup") and not arg:
                        raise SystemExit(f"{path}:{k + 1}: `docs-test: {kind}` needs a "
                                         f"{'reason' if kind == 'skip' else 'command'}")
                    markers.insert(0, (kind, arg))
                k -= 1
            blocks.append(Block(path, start + 1, text[start + 1:j], markers))
        i = j + 1
    return blocks


def mask(line, tmp):
    line = line.replace(tmp, "<tmp>")
    line = JSON_TIME.sub(r"\1<t>", line)
    line = JSON_THREADS.sub(r"\1<n>", line)
    line = RATE.sub("<rate>", line)
    line = TIME.sub("<time>", line)
    line = THREADS.sub("<n> threads", line)
    return line.rstrip()


def line_matches(expected, actual):
    if "..." not in expected:
        return expected == actual
    parts = [re.escape(p) for p in expected.split("...")]
    return re.fullmatch(".*".join(parts), actual, re.S) is not None


def lines_match(expected, actual):
    """Whether the masked lines match, `...` lines matching any run of lines."""
    memo = {}

    def go(i, j):
        key = (i, j)
        if key in memo:
            return memo[key]
        if i == len(expected):
            r = j == len(actual)
        elif expected[i] == "...":
            r = any(go(i + 1, k) for k in range(j, len(actual) + 1))
        else:
            r = j < len(actual) and line_matches(expected[i], actual[j]) and go(i + 1, j + 1)
        memo[key] = r
        return r

    return go(0, 0)


def cuda_without_device(skybake):
    """Whether this is a CUDA build on a machine without a device, as no-gpu blocks show."""
    out = subprocess.run([skybake, "--version"], capture_output=True, text=True).stdout
    return "with CUDA, no device found" in out


def run_file(path, skybake, source_dir, keep, no_gpu):
    blocks = parse(path)
    name = os.path.relpath(path, source_dir)
    if not blocks:
        print(f"{name}: no console blocks")
        return 0
    tmp = tempfile.mkdtemp(prefix="skybake-docs-")
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(os.path.abspath(skybake)) + os.pathsep + env.get("PATH", "")
    env["SKYBAKE_SOURCE_DIR"] = source_dir
    env["LC_ALL"] = "C.UTF-8"
    env["COLUMNS"] = "100"
    env.setdefault("SKYBAKE_CACHE_DIR", "off")
    failures = 0
    ran = skipped = 0
    try:
        for b in blocks:
            where = f"{name}:{b.line}"
            skip = [a for k, a in b.markers if k == "skip"]
            if skip:
                print(f"{where}: skipped: {skip[0]}")
                skipped += 1
                continue
            if not no_gpu and any(k == "no-gpu" for k, _ in b.markers):
                print(f"{where}: skipped: the output shown is that of a CUDA build without a device")
                skipped += 1
                continue
            setup_failed = False
            for k, a in b.markers:
                if k == "setup":
                    r = subprocess.run(["bash", "-c", a], cwd=tmp, env=env, stdin=subprocess.DEVNULL,
                                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                    if r.returncode != 0:
                        print(f"{where}: FAILED setup `{a}` (exit {r.returncode}):\n{r.stdout}")
                        failures += 1
                        setup_failed = True
                        break
            if setup_failed:
                continue
            t0 = time.monotonic()
            for line, cmd, expected in b.commands:
                r = subprocess.run(["bash", "-c", cmd], cwd=tmp, env=env, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
                actual = r.stdout.split("\n")
                if actual and actual[-1] == "":
                    actual.pop()
                want = [mask(e, tmp) for e in expected]
                got = [mask(a, tmp) for a in actual]
                must_fail = any(e.startswith("skybake: error:") for e in expected)
                problems = []
                if must_fail and r.returncode == 0:
                    problems.append("succeeded, but the doc shows an error")
                if not must_fail and r.returncode != 0:
                    problems.append(f"exit code {r.returncode}")
                if not lines_match(want, got):
                    problems.append("output differs")
                if problems:
                    failures += 1
                    first = cmd.split("\n")[0]
                    print(f"{name}:{line}: FAILED ({', '.join(problems)}): $ {first}")
                    print("  expected (masked):")
                    for e in want:
                        print("    | " + e)
                    print("  actual (masked):")
                    for a in got:
                        print("    | " + a)
            ran += 1
            print(f"{where}: {len(b.commands)} command(s) in {time.monotonic() - t0:.1f} s")
    finally:
        if keep:
            print(f"{name}: kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print(f"{name}: {ran} block(s) run, {skipped} skipped, {failures} failure(s)")
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--skybake", required=True, help="the skybake binary to run")
    ap.add_argument("--source-dir", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--keep", action="store_true", help="keep the temporary folders")
    ap.add_argument("files", nargs="+")
    args = ap.parse_args()
    skybake = os.path.abspath(args.skybake)
    source_dir = os.path.abspath(args.source_dir)
    no_gpu = cuda_without_device(skybake)
    failures = sum(run_file(os.path.abspath(f), skybake, source_dir, args.keep, no_gpu) for f in args.files)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
