#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks docs/scene.schema.json against the scenes of the project.

  * the schema itself is a valid JSON Schema;
  * every scene under examples/ and tests/schema/good/ is accepted;
  * every scene under tests/schema/bad/ is refused (its first line says why it is bad).

With --whitted PATH it also asks the program (`whitted convert`, which parses and validates a
scene without rendering it) and expects the same verdicts: exit status 0 for the good scenes,
2 for the bad ones. That keeps the schema and the parser in step.

Scenes are read with YAML 1.2 rules, as yaml-cpp reads them: 1e-3 is a number, yes/no/on/off
are words, and a key given twice is an error.

Needs python3-yaml and python3-jsonschema (Debian packages of the same names).
Prints one line per failure and exits 1 if there was any, 0 otherwise.
Usage: check_examples.py [--root DIR] [--whitted PATH] [-v]
"""
import argparse
import json
import re
import sys
import tempfile
from pathlib import Path

import jsonschema
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from harness import Failures, fail, run  # noqa: E402  (tests/harness.py)


class Yaml12Loader(yaml.SafeLoader):
    """SafeLoader with the YAML 1.2 core schema's plain scalars and no duplicate keys."""


Yaml12Loader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers
            if tag not in ("tag:yaml.org,2002:bool", "tag:yaml.org,2002:int", "tag:yaml.org,2002:float")]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
Yaml12Loader.add_implicit_resolver("tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
                                   list("tTfF"))
Yaml12Loader.add_implicit_resolver("tag:yaml.org,2002:int", re.compile(r"^[-+]?[0-9]+$"), list("-+0123456789"))
# Only finite decimal numbers: Whitted refuses .inf and .nan, and so does the schema (as strings).
Yaml12Loader.add_implicit_resolver("tag:yaml.org,2002:float",
                                   re.compile(r"^[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?$"),
                                   list("-+.0123456789"))


def _construct_bool(loader, node):
    return loader.construct_scalar(node).lower() == "true"


def _construct_int(loader, node):
    return int(loader.construct_scalar(node))


def _construct_float(loader, node):
    return float(loader.construct_scalar(node))


def _construct_mapping(loader, node, deep=False):
    loader.flatten_mapping(node)
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, f"key {key!r} is given twice", key_node.start_mark)
        seen.add(key)
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


Yaml12Loader.add_constructor("tag:yaml.org,2002:bool", _construct_bool)
Yaml12Loader.add_constructor("tag:yaml.org,2002:int", _construct_int)
Yaml12Loader.add_constructor("tag:yaml.org,2002:float", _construct_float)
Yaml12Loader.add_constructor("tag:yaml.org,2002:map", lambda loader, node: _construct_mapping(loader, node, True))


def load_scene(path):
    with open(path, encoding="utf-8") as f:
        return yaml.load(f, Loader=Yaml12Loader)  # noqa: S506 (a SafeLoader subclass)


def schema_errors(validator, path):
    """The schema's complaints about one scene file, as short strings (empty if it is valid)."""
    try:
        scene = load_scene(path)
    except (OSError, yaml.YAMLError) as e:
        return [f"cannot read: {' '.join(str(e).split())}"]
    errors = []
    for error in sorted(validator.iter_errors(scene), key=lambda e: [str(p) for p in e.absolute_path]):
        for detail in explain(error):
            where = "/".join(str(p) for p in detail.absolute_path) or "(top)"
            errors.append(f"{where}: {detail.message[:200]}")
    return errors


def explain(error):
    """For a oneOf/anyOf failure (an object or light of some type), the errors of the branches
    whose `type` matched, rather than "is not valid under any of the given schemas"."""
    if not error.context:
        return [error]
    branches = {}
    for sub in error.context:
        branches.setdefault(sub.relative_schema_path[0], []).append(sub)
    matching = [subs for subs in branches.values()
                if not any(s.validator == "const" and list(s.relative_path) == ["type"] for s in subs)]
    if not matching or len(matching) == len(branches):
        return [error]
    # Several branches share the type (mesh from a file, inline mesh): keep the closest ones,
    # those with the fewest complaints about the object itself.
    def shallow(subs):
        return sum(1 for s in subs if not s.relative_path)
    fewest = min(shallow(subs) for subs in matching)
    matching = [subs for subs in matching if shallow(subs) == fewest]
    return [detail for subs in matching for sub in subs for detail in explain(sub)]


def whitted_status(whitted, path, scratch):
    """`whitted convert` parses and validates the scene without rendering it: 0 = accepted. To
    Whitted's own YAML, so that what only the POV-Ray converter refuses (the course's conventions)
    does not count against the scene."""
    try:
        result = run([whitted, "convert", str(path), str(Path(scratch) / "scene.yaml")], expect=None, timeout=120)
    except OSError as e:
        return None, f"cannot run {whitted}: {e}"
    return result.returncode, result.stderr.strip()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = Path(__file__).resolve().parent
    parser.add_argument("--root", type=Path, default=here.parent.parent, help="the repository (default: ../..)")
    parser.add_argument("--whitted", help="also check the verdicts against this whitted program")
    parser.add_argument("-v", "--verbose", action="store_true", help="print every scene checked")
    args = parser.parse_args()

    root = args.root.resolve()
    schema_path = root / "docs" / "scene.schema.json"
    failures = Failures()
    try:
        schema = json.loads(schema_path.read_text(encoding="utf-8"))
        validator_class = jsonschema.validators.validator_for(schema)
        validator_class.check_schema(schema)
    except (OSError, ValueError, jsonschema.exceptions.SchemaError) as e:
        fail(f"{schema_path}: not a usable JSON Schema: {e}")
    validator = validator_class(schema)

    def scenes(folder):
        return sorted(p for p in folder.rglob("*") if p.suffix in (".yaml", ".yml", ".json") and p.is_file())

    good = scenes(root / "examples") + scenes(here / "good")
    bad = scenes(here / "bad")
    if not good or not bad:
        fail(f"found {len(good)} good and {len(bad)} bad scenes; expected some of each")

    def shown(path):
        return path.relative_to(root) if path.is_relative_to(root) else path

    with tempfile.TemporaryDirectory() as scratch:
        for path in good:
            name = shown(path)
            for error in schema_errors(validator, path):
                failures.fail(f"{name}: the schema refuses a valid scene: {error}")
            if args.whitted:
                status, message = whitted_status(args.whitted, path, scratch)
                if status != 0:
                    failures.fail(f"{name}: whitted refuses it (exit {status}): {message}")
            if args.verbose:
                print(f"checked {name}")
        for path in bad:
            name = shown(path)
            reason = path.read_text(encoding="utf-8").splitlines()[0].lstrip("# ").strip()
            if not schema_errors(validator, path):
                failures.fail(f"{name}: the schema accepts a bad scene ({reason})")
            if args.whitted:
                status, message = whitted_status(args.whitted, path, scratch)
                if status != 2:
                    failures.fail(f"{name}: whitted exits {status}, expected 2 ({reason}): {message}")
            if args.verbose:
                print(f"checked {name}: {reason}")

    checked = "schema and whitted" if args.whitted else "schema"
    print(f"{len(good)} valid and {len(bad)} invalid scenes checked ({checked})")
    failures.finish("all as expected")


if __name__ == "__main__":
    main()
