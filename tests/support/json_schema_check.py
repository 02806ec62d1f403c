#!/usr/bin/python3
# json_schema_check.py SCHEMA.json DOCUMENT.json [DOCUMENT.json ...]
# json_schema_check.py --lint SCHEMA.json [SCHEMA.json ...]
#
# Checks that each document is valid against the JSON Schema (draft 2020-12) that documents it in
# docs/schemas/. The schemas forbid undocumented fields (additionalProperties: false), so a field a
# tool starts writing without describing it fails here. Uses Debian's python3-jsonschema rather
# than a hand-written validator. Exit 0 when every document is valid, 1 otherwise (every error
# printed with its JSON path), 2 when a file cannot be read.
#
# --lint checks the schemas themselves against docs/JSON.md's rules, which a validator cannot see:
# every object schema ("type": "object") sets additionalProperties to false, and every property it
# declares has a non-empty description (meaning and unit). Exit 0 when every schema keeps them, 1
# otherwise (each lapse printed with its schema path), 2 when a schema cannot be read.
import json
import sys

import jsonschema


def lint_problems(schema):
    problems = []

    def walk(node, where):
        if isinstance(node, dict):
            # An "if" only tests a document; every schema that describes one must say it is an object.
            if "properties" in node and node.get("type") != "object" and not where.endswith("/if"):
                problems.append(f"{where}: declares properties but not \"type\": \"object\"")
            if node.get("type") == "object":
                if node.get("additionalProperties") is not False:
                    problems.append(f"{where}: object schema without additionalProperties: false")
                for name, sub in (node.get("properties") or {}).items():
                    if not isinstance(sub, dict) or not str(sub.get("description", "")).strip():
                        problems.append(f"{where}/properties/{name}: no description")
            for key, value in node.items():
                walk(value, f"{where}/{key}")
        elif isinstance(node, list):
            for i, value in enumerate(node):
                walk(value, f"{where}/{i}")

    walk(schema, "#")
    return problems


def lint(paths):
    failed = False
    for path in paths:
        try:
            with open(path, encoding="utf-8") as f:
                schema = json.load(f)
            jsonschema.Draft202012Validator.check_schema(schema)
        except (OSError, ValueError, jsonschema.SchemaError) as e:
            print(f"{path}: not a usable schema: {e}", file=sys.stderr)
            return 2
        problems = lint_problems(schema)
        for p in problems:
            print(f"{path}: {p}", file=sys.stderr)
        if problems:
            failed = True
        else:
            print(f"{path}: every object closed, every property described")
    return 1 if failed else 0


def main(argv):
    if len(argv) >= 3 and argv[1] == "--lint":
        return lint(argv[2:])
    if len(argv) < 3:
        print("usage: json_schema_check.py SCHEMA.json DOCUMENT.json...\n"
              "       json_schema_check.py --lint SCHEMA.json...", file=sys.stderr)
        return 2
    try:
        with open(argv[1], encoding="utf-8") as f:
            schema = json.load(f)
        jsonschema.Draft202012Validator.check_schema(schema)
    except (OSError, ValueError, jsonschema.SchemaError) as e:
        print(f"{argv[1]}: not a usable schema: {e}", file=sys.stderr)
        return 2
    validator = jsonschema.Draft202012Validator(schema)
    failed = False
    for path in argv[2:]:
        try:
            with open(path, encoding="utf-8") as f:
                doc = json.load(f)
        except (OSError, ValueError) as e:
            print(f"{path}: cannot read JSON: {e}", file=sys.stderr)
            return 2
        errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path))
        for e in errors:
            where = "/".join(str(p) for p in e.absolute_path) or "(root)"
            print(f"{path}: {where}: {e.message}", file=sys.stderr)
        if errors:
            failed = True
        else:
            print(f"{path}: valid against {argv[1]}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
