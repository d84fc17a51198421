#!/usr/bin/env python3
"""Fails when a function (or struct) in the integrator's stages is longer
than the limit: the path tracer stays a loop over stages that each fit on a
screen or two (docs/architecture.md).

  scripts/check_function_length.py [--limit 100] [FILES...]

Default files: src/integrator/*.h, the guides' per-path hooks (src/guidecache/**/*path_guide*.h)
and src/guidecache/path_learning.h.
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
    """(first line number, first line, length) of each function defined at
    namespace scope or in a struct (a struct's body is a scope, not a block)."""
    depth, scopes, start = 0, [0], None
    lines = text.split("\n")
    for n, raw in enumerate(lines, 1):
        line = re.sub(r"//.*", "", raw)
        for ch in line:
            if ch == "{":
                depth += 1
                if start is None and depth - 1 == scopes[-1]:
                    if re.match(r"\s*(namespace|struct|class|union|enum)\b", line) or (
                            re.match(r"\s*(namespace|struct|class|union|enum)\b", lines[n - 2]) and line.strip() == "{"):
                        scopes.append(depth)
                    else:
                        start = n
            elif ch == "}":
                depth -= 1
                if start is not None and depth == scopes[-1]:
                    # The definition's head: back to the line after the previous statement, block or comment.
                    head = start
                    while head > 1 and lines[head - 2].strip() and not lines[head - 2].strip().endswith((";", "}", "{")) \
                            and not lines[head - 2].lstrip().startswith(("//", "template")):
                        head -= 1
                    yield head, lines[head - 1].strip(), n - head + 1
                    start = None
                elif start is None and len(scopes) > 1 and depth == scopes[-1] - 1:
                    scopes.pop()


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--limit", type=int, default=100)
    p.add_argument("files", nargs="*")
    args = p.parse_args()
    files = [pathlib.Path(f) for f in args.files] or sorted((ROOT / "src/integrator").glob("*.h")) + sorted(
        (ROOT / "src/guidecache").glob("**/*path_guide*.h")) + [ROOT / "src/guidecache/path_learning.h"]
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
