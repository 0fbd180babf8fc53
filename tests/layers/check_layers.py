#!/usr/bin/env python3
"""The house's layers, checked on the includes (docs/architecture.md).

src/ holds one folder per layer, bottom to top in LAYERS. A file may include its own layer and the
layers below it, never one above. Beside that order, three graphs must have no cycle: the top-level
folders of the repository (src, include, benchmarks, apps, python, fuzz, tests), every folder under
src/ (accel/common, accel/bvh, ... count apart), and the files themselves.

Usage: check_layers.py ROOT       check the checkout at ROOT; one line per violation, exit 1 if any
       check_layers.py --self-test  plant each kind of violation in a scratch tree and expect it found
"""
import os
import re
import shutil
import sys
import tempfile

# Bottom to top. The order is the one src/CMakeLists.txt builds them in.
LAYERS = ["core", "scene", "film", "accel", "shading", "importers", "integrator", "output", "session", "reference"]
# The consumers above src/ (the top-level folders whose code includes src/).
TOP_LEVEL = ["src", "include", "benchmarks", "apps", "python", "fuzz", "tests"]

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)


def source_files(root):
    for top in TOP_LEVEL:
        base = os.path.join(root, top)
        for dirpath, _, names in os.walk(base):
            for name in sorted(names):
                if name.endswith((".h", ".cpp")):
                    path = os.path.join(dirpath, name)
                    yield os.path.relpath(path, root).replace(os.sep, "/")


def resolve(root, including, name):
    """The repository path an include names: src/-relative, root-relative, or beside the file."""
    for candidate in ("src/" + name, name, os.path.join(os.path.dirname(including), name)):
        candidate = os.path.normpath(candidate).replace(os.sep, "/")
        if os.path.isfile(os.path.join(root, candidate)):
            return candidate
    return None  # a system or third-party header, or generated


def find_cycle(graph):
    """One cycle of `graph` (node -> set of nodes) as a list of nodes, or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    sys.setrecursionlimit(10000)
    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def check(root):
    problems = []
    files, folders, tops = {}, {}, {}
    for path in source_files(root):
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        deps = set()
        for name in INCLUDE.findall(text):
            target = resolve(root, path, name)
            if target and target != path:
                deps.add(target)
        files[path] = deps
        for target in deps:
            a, b = path.split("/")[0], target.split("/")[0]
            if a != b:
                tops.setdefault(a, set()).add(b)
            if path.startswith("src/") and target.startswith("src/"):
                fa, fb = os.path.dirname(path), os.path.dirname(target)
                if fa != fb:
                    folders.setdefault(fa, set()).add(fb)
                la, lb = path.split("/")[1], target.split("/")[1]
                if la not in LAYERS or lb not in LAYERS:
                    problems.append(f"{path}: folder src/{la if la not in LAYERS else lb} is not a layer "
                                    f"(tests/layers/check_layers.py LAYERS)")
                elif LAYERS.index(lb) > LAYERS.index(la):
                    problems.append(f"{path}: includes {target}, a layer above ({la} < {lb})")
            elif path.startswith("src/"):
                problems.append(f"{path}: includes {target}, outside src/")
    for what, graph in (("top-level folders", tops), ("folders", folders), ("files", files)):
        cycle = find_cycle(graph)
        if cycle:
            problems.append(f"include cycle between {what}: {' -> '.join(cycle)}")
    return problems


def self_test():
    def tree(files):
        root = tempfile.mkdtemp(prefix="layers_")
        for path, text in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(path)), exist_ok=True)
            with open(os.path.join(root, path), "w") as f:
                f.write(text)
        return root

    clean = {"src/core/a.h": "", "src/scene/b.h": '#include "core/a.h"\n', "apps/x/main.cpp": '#include "scene/b.h"\n'}
    cases = {
        "clean": (clean, None),
        "upward": ({**clean, "src/core/c.h": '#include "scene/b.h"\n'}, "a layer above"),
        "outside": ({**clean, "src/core/c.h": '#include "apps/x/main.cpp"\n'}, "outside src/"),
        "folders": ({**clean, "src/accel/x/p.h": '#include "accel/y/q.h"\n', "src/accel/y/q.h": "",
                     "src/accel/y/r.h": '#include "accel/x/s.h"\n', "src/accel/x/s.h": ""},
                    "cycle between folders"),
        "files": ({**clean, "src/core/p.h": '#include "core/q.h"\n', "src/core/q.h": '#include "core/p.h"\n'},
                  "cycle between files"),
        "tops": ({**clean, "benchmarks/b.h": '#include "apps/x/main.cpp"\n', "apps/x/y.h": '#include "benchmarks/b.h"\n'},
                 "cycle between top-level folders"),
    }
    failed = 0
    for name, (files, expect) in cases.items():
        root = tree(files)
        try:
            problems = check(root)
        finally:
            shutil.rmtree(root, ignore_errors=True)
        ok = (not problems) if expect is None else any(expect in p for p in problems)
        print(f"{'ok' if ok else 'FAILED'}: {name}: {problems or 'no problem'}")
        failed += not ok
    return 1 if failed else 0


def run_checker(check, self_test, doc, ok_line):
    """The command line of a checker: ROOT (print each problem, exit 1 if any) or --self-test."""
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(doc, file=sys.stderr)
        return 2
    problems = check(sys.argv[1])
    for p in problems:
        print(p)
    if not problems:
        print(ok_line)
    return 1 if problems else 0


def main():
    return run_checker(check, self_test, __doc__,
                       f"layers: {' -> '.join(LAYERS)}; no include goes up, no cycle")


if __name__ == "__main__":
    sys.exit(main())
