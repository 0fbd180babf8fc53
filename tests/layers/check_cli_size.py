#!/usr/bin/env python3
"""The CLI stays slim (docs/architecture.md): apps/whitted/main.cpp at most 300 lines, no function in
apps/whitted longer than 60 lines (from its signature's first line to its closing brace).

Usage: check_cli_size.py ROOT        one line per violation, exit 1 if any
       check_cli_size.py --self-test a long function planted in a scratch file must be found
"""
import os
import re
import sys
import tempfile

from check_layers import run_checker

MAX_MAIN_LINES = 300
MAX_FUNCTION_LINES = 60
# A function definition's first line: a return type or scope, a name, "(" and no ";" (not a call
# statement or declaration), at namespace or class level (indented at most 4 spaces).
SIGNATURE = re.compile(r'^ {0,4}(?=\S)(?!(?:return|if|for|while|switch|else|case)\b)[\w:<>,&*~ \[\]"]+?\b[\w:~]+\s*\(')


def functions(lines):
    """(name line, first line number, length) of each function body in a C++ file."""
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if SIGNATURE.match(line) and not line.rstrip().endswith(";") and "=" not in line.split("(")[0]:
            # the body opens on this line or the next few, before any ';'
            j, depth, opened = i, 0, False
            while j < len(lines):
                text = re.sub(r'"(\\.|[^"\\])*"', '""', lines[j].split("//")[0])
                if not opened and ";" in text and "{" not in text:
                    break
                depth += text.count("{") - text.count("}")
                opened = opened or "{" in text
                if opened and depth <= 0:
                    out.append((line.strip(), i + 1, j - i + 1))
                    break
                j += 1
            if opened:
                i = j + 1
                continue
        i += 1
    return out


def check(root):
    problems = []
    app = os.path.join(root, "apps", "whitted")
    with open(os.path.join(app, "main.cpp")) as f:
        n = len(f.read().splitlines())
    if n > MAX_MAIN_LINES:
        problems.append(f"apps/whitted/main.cpp: {n} lines (at most {MAX_MAIN_LINES})")
    for name in sorted(os.listdir(app)):
        if not name.endswith(".cpp"):
            continue
        with open(os.path.join(app, name)) as f:
            lines = f.read().splitlines()
        for signature, first, length in functions(lines):
            if length > MAX_FUNCTION_LINES:
                problems.append(f"apps/whitted/{name}:{first}: a function of {length} lines (at most "
                                f"{MAX_FUNCTION_LINES}): {signature[:80]}")
    return problems


def self_test():
    with tempfile.TemporaryDirectory(prefix="cli_size_") as root:
        os.makedirs(os.path.join(root, "apps", "whitted"))
        body = "\n".join(f"    x += {i};" for i in range(70))
        with open(os.path.join(root, "apps", "whitted", "main.cpp"), "w") as f:
            f.write("int short_one(int x) {\n    return x;\n}\n\nint long_one(int x) {\n" + body + "\n    return x;\n}\n")
        problems = check(root)
    ok = len(problems) == 1 and "long_one" in problems[0] and "73 lines" in problems[0]
    print(("ok" if ok else "FAILED") + ": " + "; ".join(problems))
    return 0 if ok else 1


def main():
    return run_checker(check, self_test, __doc__,
                       f"apps/whitted: main.cpp within {MAX_MAIN_LINES} lines, every function within {MAX_FUNCTION_LINES}")


if __name__ == "__main__":
    sys.exit(main())
