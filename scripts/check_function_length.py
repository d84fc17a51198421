#!/usr/bin/env python3
"""Fails when a function (or struct) in the integrator's stages is longer
than the limit: the path tracer stays a loop over stages that each fit on a
screen or two (docs/architecture.md).

  scripts/check_function_length.py [--limit 100] [FILES...]

Default files: src/kernels/integrator*.h and src/kernels/path_learning.h.
Counts the lines of each brace block opened at namespace scope (comments
and strings are not parsed: braces in them would miscount, so keep them out).
Prints file:line, the definition's first line and its length for each one
over the limit; exit status 1 if any.
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def blocks(text):
    """(first line number, first line, length) of each block at namespace scope."""
    depth, namespaces, start = 0, [], None
    lines = text.split("\n")
    for n, raw in enumerate(lines, 1):
        line = re.sub(r"//.*", "", raw)
        for ch in line:
            if ch == "{":
                if re.match(r"\s*namespace\b", line) and start is None:
                    namespaces.append(depth)
                elif depth == len(namespaces) and start is None:
                    start = n
                depth += 1
            elif ch == "}":
                depth -= 1
                if namespaces and depth == namespaces[-1] and start is None:
                    namespaces.pop()
                elif start is not None and depth == len(namespaces):
                    # The definition's head: back to the line after the previous block or blank line.
                    head = start
                    while head > 1 and lines[head - 2].strip() and not lines[head - 2].strip().endswith((";", "}")) \
                            and not lines[head - 2].lstrip().startswith("//"):
                        head -= 1
                    yield head, lines[head - 1].strip(), n - head + 1
                    start = None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--limit", type=int, default=100)
    p.add_argument("files", nargs="*")
    args = p.parse_args()
    files = [pathlib.Path(f) for f in args.files] or sorted((ROOT / "src/kernels").glob("integrator*.h")) + [
        ROOT / "src/kernels/path_learning.h"]
    too_long = 0
    for f in files:
        for line, head, length in blocks(f.read_text()):
            if length > args.limit:
                too_long += 1
                print(f"{f}:{line}: {length} lines (limit {args.limit}): {head}")
    if too_long:
        print(f"{too_long} definitions over {args.limit} lines: split them into stages")
        return 1
    print(f"{len(files)} files: every definition within {args.limit} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
