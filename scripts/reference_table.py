#!/usr/bin/env python3
"""The table of docs/measurements/accuracy.md from test_reference_compare's output.

Usage: build/release/tests/test_reference_compare | python3 scripts/reference_table.py
"""
import collections
import re
import sys


def main():
    summary, causes, order = {}, collections.defaultdict(collections.Counter), []
    for line in sys.stdin:
        m = re.match(r"^\[([^\]]+)\] (\d+x\d+): PSNR ([0-9.]+) dB, max rel ([0-9.e+-]+) "
                     r"\(same-tree pixels (\d+/\d+): max rel ([0-9.e+-]+)\), (\d+) pixel.*within ([0-9.]+) x", line)
        if m:
            summary[m.group(1)] = m.groups()[1:]
            order.append(m.group(1))
            continue
        m = re.match(r"^\[([^\]]+)\]\s+(\d+)\s+(.*)$", line)
        if m:  # a cause line: "[case]   count  cause (detail)"
            cause = m.group(3)
            key = "secondary ray: another primitive" if cause.startswith("secondary") else cause.split(" (")[0].split(":")[0]
            causes[m.group(1)][key] += int(m.group(2))
    if not order:
        sys.exit("reference_table: no case summaries in the input")
    print("| case | size | PSNR (dB) | max rel | max rel, same tree | same-tree pixels | pixels > 1e-5 | causes "
          "| camera-ray barycentrics (2^-24 t / altitude) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for case in order:
        size, psnr, max_rel, same, max_same, beyond, bary = summary[case]
        listed = "; ".join(f"{n} {k}" for k, n in causes[case].most_common()) or "–"
        print(f"| {case} | {size} | {psnr} | {max_rel} | {max_same} | {same} | {beyond} | {listed} | {bary} |")


if __name__ == "__main__":
    main()
