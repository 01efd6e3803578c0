"""Validates effect files against docs/effect.schema.json (draft 2020-12): every built-in
sample must pass, and tests/effect/data/typo.json (an unknown field) must not, so the schema
neither refuses real effects nor accepts everything."""
import glob
import json
import re
import sys

import jsonschema

src = sys.argv[1]
schema = json.load(open(f"{src}/docs/effect.schema.json"))
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)


def load(path):
    text = re.sub(r"(?m)^\s*//.*$", "", open(path).read())  # effect files allow // comments
    return json.loads(text)


failed = False
for path in sorted(glob.glob(f"{src}/samples/effects/*.json")):
    for e in validator.iter_errors(load(path)):
        print(f"{path}: {list(e.absolute_path)}: {e.message}")
        failed = True
if not list(validator.iter_errors(load(f"{src}/tests/effect/data/typo.json"))):
    print("typo.json (an unknown field) passes the schema")
    failed = True
sys.exit(1 if failed else 0)
