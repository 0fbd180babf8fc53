#!/usr/bin/env python3
"""Validates scene files against docs/scene-format.schema.json (JSON Schema draft 2020-12).

usage: validate_schema.py SCHEMA DIR_OR_FILE...   (every *.json in a folder, not recursive)

Also checks that a few documents the importer refuses are refused by the schema too, so the
schema cannot silently accept everything. Exit status 0 when all is as expected.
"""
import json
import pathlib
import sys

import jsonschema


def main() -> int:
    schema_path = pathlib.Path(sys.argv[1])
    schema = json.loads(schema_path.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    failures = 0
    checked = 0
    for arg in sys.argv[2:]:
        p = pathlib.Path(arg)
        files = sorted(p.glob("*.json")) if p.is_dir() else [p] if p.exists() else []
        for f in files:
            if f.resolve() == schema_path.resolve():
                continue
            checked += 1
            errors = sorted(validator.iter_errors(json.loads(f.read_text())), key=lambda e: list(e.path))
            for e in errors:
                failures += 1
                print(f"{f}: /{'/'.join(str(x) for x in e.path)}: {e.message}")
    # Documents the importer refuses must fail validation too.
    refused = [
        {},
        {"version": 2},
        {"version": 1, "light": []},
        {"version": 1, "objects": [{"type": "sphere", "center": [0, 0, 0], "radus": 1}]},
        {"version": 1, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}]},
        {"version": 1, "materials": {"m": {"kd": 1, "color": 1}}},
        {"version": 1, "materials": {"m": {"ks": "shiny"}}},
        {"version": 1, "objects": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1],
                                    "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], "scale": 2}}]},
        {"version": 1, "camera": {"position": [0, 0, 0], "size": 3}},
        {"version": 1, "lights": [{"type": "spot", "position": [0, 0, 0]}]},
        {"version": 1, "lights": [{"type": "directional", "direction": [0, -1, 0], "range": 1}]},
        {"version": 1, "include": [{"file": "x.obj"}]},
        {"version": 1, "render": {"aa": "super"}},
    ]
    for doc in refused:
        if validator.is_valid(doc):
            failures += 1
            print(f"schema accepts a document the importer refuses: {json.dumps(doc)}")
    print(f"{checked} file(s) checked, {len(refused)} refusals checked, {failures} problem(s)")
    return 1 if failures or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
