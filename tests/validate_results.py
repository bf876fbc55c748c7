#!/usr/bin/python3
"""Validate a mechbench results.json against harness/report/results.schema.json.

usage: validate_results.py SCHEMA JSON

Exit 0 when valid, 1 with every violation listed when not, 2 on bad usage or unreadable files,
77 (ctest's skip code) when python3's jsonschema module is missing (Debian: python3-jsonschema).
"""
import json
import os
import sys
import urllib.parse
import urllib.request


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    schema_path, data_path = argv[1], argv[2]
    try:
        import jsonschema
    except ImportError as e:
        print(f"skipped: python3 module jsonschema is not installed ({e}); "
              "on Debian: apt-get install python3-jsonschema", file=sys.stderr)
        return 77
    try:
        with open(schema_path, encoding="utf-8") as f:
            schema = json.load(f)
        with open(data_path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2

    # The schema's $id is relative ("mechbench-results/1"). Resolved against the file's own URI
    # it becomes absolute, so "#/$defs/…" references stay inside this document with every
    # jsonschema version (4.10 joins a relative $id with itself and then looks it up as a URL).
    file_uri = urllib.parse.urljoin("file:", urllib.request.pathname2url(os.path.abspath(schema_path)))
    schema = dict(schema)
    schema["$id"] = urllib.parse.urljoin(file_uri, schema.get("$id", ""))

    cls = jsonschema.validators.validator_for(schema)
    try:
        cls.check_schema(schema)
    except jsonschema.exceptions.SchemaError as e:
        print(f"{schema_path}: not a valid JSON Schema: {e.message}", file=sys.stderr)
        return 2
    validator = cls(schema, format_checker=getattr(cls, "FORMAT_CHECKER", None))
    errors = sorted(validator.iter_errors(data), key=lambda e: list(e.absolute_path))
    if not errors:
        print(f"{data_path}: valid against {schema_path} ({cls.__name__}, jsonschema {version()})")
        return 0
    for e in errors:
        where = "/".join(str(p) for p in e.absolute_path) or "(top level)"
        if e.validator == "oneOf" and e.context:
            # A record matching none of the kinds: report the branch of its own kind.
            branches = {}
            for sub in e.context:
                branches.setdefault(sub.relative_schema_path[0], []).append(sub)
            own = [subs for subs in branches.values()
                   if not any(s.validator == "const" and list(s.relative_path) == ["kind"] for s in subs)]
            subs = own[0] if own else e.context
            kind = e.instance.get("kind") if isinstance(e.instance, dict) else None
            print(f"{data_path}: {where}: not a valid {kind or 'record'} record:", file=sys.stderr)
            for sub in subs:
                sub_where = "/".join(str(p) for p in sub.absolute_path) or where
                print(f"    {sub_where}: {sub.message}", file=sys.stderr)
        else:
            print(f"{data_path}: {where}: {e.message}", file=sys.stderr)
    print(f"{len(errors)} error(s)", file=sys.stderr)
    return 1


def version():
    try:
        from importlib.metadata import version as v
        return v("jsonschema")
    except Exception:  # noqa: BLE001 - only for the message
        return "?"


if __name__ == "__main__":
    sys.exit(main(sys.argv))
