#!/usr/bin/env python3
"""Checks that src/'s folders include each other in one direction.

    app -> farm roles (master, worker -> comm) -> render -> scene, guidecache -> kernels

Reads every #include under src/ and prints one line per include that goes
the wrong way (file:line, the include, the rule it breaks); exits 1 if there
is any. The rules are the tables below: MAY_INCLUDE (folder to folder),
NEVER_REACHES (through any chain of includes), LIBRARY_HOMES (<...> headers
kept in their files), and the named EXCEPTIONS. docs/architecture.md shows
MAY_INCLUDE as --table prints it; --docs checks that it still does.

    scripts/check_layers.py [--src DIR] [--docs FILE] [--table] [--self-test]

Python 3 standard library only.
"""

import argparse
import os
import re
import sys
import tempfile

# Which folders of src/ a folder's files may include, besides their own.
# Top to bottom; a folder never includes one above it, nor a sibling not
# listed (master and worker do not include each other; neither do scene
# and guidecache).
MAY_INCLUDE = {
    "app": ["master", "worker", "comm", "render", "integrator", "scene", "guidecache", "kernels"],
    "master": ["comm", "render", "integrator", "scene", "guidecache", "kernels"],
    "worker": ["comm", "render", "integrator", "scene", "guidecache", "kernels"],
    "comm": ["render", "scene", "guidecache", "kernels"],
    "render": ["integrator", "scene", "guidecache", "kernels"],
    "integrator": ["guidecache", "kernels"],
    "scene": ["kernels"],
    "guidecache": ["kernels"],
    "kernels": [],
}

# What a folder must not reach through any chain of includes, and why.
NEVER_REACHES = {
    "comm": {
        "integrator/integrator.h": "the farm's messages and transport are plain structs: "
        "changing the integrator must not rebuild or change them",
    },
}

# Library headers (an #include <...> starting with the key) and the only
# files, as globs relative to src/, that may include them.
LIBRARY_HOMES = {
    "mpi.h": ["comm/mpi_transport.*"],
    "embree3/": ["render/embree_backend.*"],
    "cuda_runtime": ["render/cuda_*"],
}

# Includes the tables forbid that are allowed for now: (file, include) -> why.
EXCEPTIONS = {
    # (including file, included file): why. None today: a new entry is a
    # cycle to remove, named here until it is.
}

SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".cu", ".cuh", ".inl")
QUOTED = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
ANGLED = re.compile(r"^\s*#\s*include\s*<([^>]+)>")


def folder_of(rel):
    """src-relative path -> its top-level folder ('' for files directly in src/)."""
    return rel.split("/", 1)[0] if "/" in rel else ""


def read_includes(src):
    """{src-relative path: [(line, kind, text)]} for every source file under src."""
    files = {}
    for root, dirs, names in os.walk(src):
        dirs.sort()
        for name in sorted(names):
            if not name.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(root, name)
            rel = os.path.relpath(path, src).replace(os.sep, "/")
            incs = []
            with open(path, encoding="utf-8", errors="replace") as f:
                for n, line in enumerate(f, 1):
                    m = QUOTED.match(line)
                    if m:
                        incs.append((n, '"', m.group(1)))
                        continue
                    m = ANGLED.match(line)
                    if m:
                        incs.append((n, "<", m.group(1)))
            files[rel] = incs
    return files


def resolve(rel, text, files):
    """Where #include "text" in src/rel leads, src-relative: beside the file
    first (as the compiler looks), then from src/. None: not under src/."""
    here = os.path.dirname(rel)
    for cand in (os.path.normpath(os.path.join(here, text)), os.path.normpath(text)):
        cand = cand.replace(os.sep, "/")
        if cand in files:
            return cand
    return None


def glob_match(rel, pattern):
    return re.fullmatch(re.escape(pattern).replace(r"\*", "[^/]*"), rel) is not None


def chain_to(start, goal, resolved):
    """The shortest include chain from start to goal ([start, ..., goal]), or None."""
    parent = {start: None}
    queue = [start]
    for node in queue:
        if node == goal:
            chain = []
            while node is not None:
                chain.append(node)
                node = parent[node]
            return chain[::-1]
        for _, _, target in resolved.get(node, []):
            if target is not None and target not in parent:
                parent[target] = node
                queue.append(target)
    return None


def check(src):
    """Violations as 'src/file:line: #include ...: rule' lines, sorted."""
    files = read_includes(src)
    out = []

    def report(rel, line, kind, text, why):
        shown = f'"{text}"' if kind == '"' else f"<{text}>"
        out.append((rel, line, f"src/{rel}:{line}: #include {shown}: {why}"))

    # Every quoted include, resolved: {file: [(line, text, target or None)]}.
    resolved = {rel: [(line, text, resolve(rel, text, files)) for line, kind, text in incs if kind == '"']
                for rel, incs in files.items()}

    for rel, incs in files.items():
        folder = folder_of(rel)
        if folder not in MAY_INCLUDE:
            out.append((rel, 0, f"src/{rel}: src/{folder or '.'}/ is in no layer: add it to MAY_INCLUDE "
                        "(scripts/check_layers.py) and docs/architecture.md"))
            continue
        for line, kind, text in incs:
            if kind == "<":
                for prefix, homes in LIBRARY_HOMES.items():
                    if text.startswith(prefix) and not any(glob_match(rel, h) for h in homes):
                        report(rel, line, kind, text, f"<{prefix}...> belongs in {', '.join(homes)} only")
                continue
            target = resolve(rel, text, files)
            if target is None:
                continue  # not under src/ (generated, or a library's quoted header)
            to = folder_of(target)
            if to == folder or (rel, target) in EXCEPTIONS:
                continue
            if to not in MAY_INCLUDE[folder]:
                allowed = ", ".join(MAY_INCLUDE[folder]) or "nothing else"
                report(rel, line, kind, text,
                       f"{folder}/ may not include {to or '.'}/ ({folder}/ may include: {allowed})")
        for banned, why in NEVER_REACHES.get(folder, {}).items():
            for line, text, target in resolved[rel]:
                chain = chain_to(target, banned, resolved) if target is not None else None
                if chain:
                    report(rel, line, '"', text,
                           f"{folder}/ must never reach {banned} ({why}); via {' -> '.join(chain)}")

    for rel, target in EXCEPTIONS:
        if not any(t == target for _, _, t in resolved.get(rel, [])):
            out.append((rel, 0, f"src/{rel}: the exception for {target} (scripts/check_layers.py) "
                        "is no longer needed: delete it"))
    return [msg for _, _, msg in sorted(out)]


def table_markdown():
    """MAY_INCLUDE as docs/architecture.md shows it."""
    rows = ["| folder | may include (besides itself) |", "|---|---|"]
    for folder, allowed in MAY_INCLUDE.items():
        rows.append(f"| `{folder}/` | {', '.join(f'`{a}/`' for a in allowed) or '(nothing)'} |")
    return "\n".join(rows)


def check_docs(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if table_markdown() in text:
        return []
    return [f"{path}: its layer table differs from MAY_INCLUDE (scripts/check_layers.py --table prints it)"]


def self_test():
    """The check on small trees: it passes a clean one and names each kind of violation."""
    cases = [
        # (files: {path: text}, expected substrings of the violations, in order; [] = clean)
        ({"kernels/a.h": "", "scene/s.h": '#include "kernels/a.h"\n', "render/r.h": '#include "scene/s.h"\n',
          "comm/p.h": '#include "render/r.h"\n#include <vector>\n', "master/m.cpp": '#include "comm/p.h"\n',
          "app/main.cpp": '#include "master/m.h"\n#include "worker/w.h"\n'}, []),
        ({"kernels/a.h": "", "render/r.h": '#include "kernels/a.h"\n', "kernels/b.h": '#include "render/r.h"\n'},
         ['src/kernels/b.h:1: #include "render/r.h": kernels/ may not include render/']),
        ({"master/m.h": "", "worker/w.cpp": '// x\n#include "master/m.h"\n'},
         ['src/worker/w.cpp:2: #include "master/m.h": worker/ may not include master/']),
        ({"integrator/integrator.h": "", "render/i.h": '#include "integrator/integrator.h"\n', "render/t.h": '#include "render/i.h"\n',
          "comm/p.h": '#include "render/t.h"\n'},
         ['src/comm/p.h:1: #include "render/t.h": comm/ must never reach integrator/integrator.h',
          "via render/t.h -> render/i.h -> integrator/integrator.h"]),
        ({"kernels/a.h": "", "guidecache/g.h": '#include "kernels/a.h"\n', "kernels/b.h": '#include "guidecache/g.h"\n'},
         ['src/kernels/b.h:1: #include "guidecache/g.h": kernels/ may not include guidecache/']),
        ({"guidecache/g.h": "", "integrator/i.h": '#include "guidecache/g.h"\n', "guidecache/h.h": '#include "integrator/i.h"\n'},
         ['src/guidecache/h.h:1: #include "integrator/i.h": guidecache/ may not include integrator/']),
        ({"render/x.cpp": "#include <mpi.h>\n", "comm/mpi_transport.cpp": "#include <mpi.h>\n"},
         ["src/render/x.cpp:1: #include <mpi.h>: <mpi.h...> belongs in comm/mpi_transport.* only"]),
        ({"farm/x.cpp": '#include "kernels/a.h"\n', "kernels/a.h": ""}, ["src/farm/ is in no layer"]),
    ]
    failures = 0
    for i, (tree, expected) in enumerate(cases):
        with tempfile.TemporaryDirectory() as d:
            for rel, text in tree.items():
                os.makedirs(os.path.join(d, os.path.dirname(rel)), exist_ok=True)
                with open(os.path.join(d, rel), "w", encoding="utf-8") as f:
                    f.write(text)
            got = check(d)
        text = "\n".join(got)
        ok = (not got) if not expected else (len(got) == 1 and all(e in text for e in expected))
        if not ok:
            failures += 1
            print(f"self-test case {i}: expected {expected or 'no violations'}, got:\n  " + "\n  ".join(got or ["none"]))
    if table_markdown().count("\n") != len(MAY_INCLUDE) + 1:
        failures += 1
        print("self-test: the table has a row per folder")
    print(f"self-test: {len(cases) - failures} of {len(cases)} cases pass" if failures else
          f"self-test: all {len(cases)} cases pass")
    return 1 if failures else 0


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--src", default=os.path.join(here, "..", "src"), help="the source tree (default: ../src)")
    ap.add_argument("--docs", help="also check that this file shows the layer table")
    ap.add_argument("--table", action="store_true", help="print the layer table (markdown) and exit")
    ap.add_argument("--self-test", action="store_true", help="check the check on small trees and exit")
    args = ap.parse_args()
    if args.table:
        print(table_markdown())
        return 0
    if args.self_test:
        return self_test()
    problems = check(args.src)
    if args.docs:
        problems += check_docs(args.docs)
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include(s) against the layering (scripts/check_layers.py)", file=sys.stderr)
        return 1
    print(f"layering: {len(read_includes(args.src))} files, every include goes down")
    return 0


if __name__ == "__main__":
    sys.exit(main())
