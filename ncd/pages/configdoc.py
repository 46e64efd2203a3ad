"""``config/README.md`` from the schemas: every section and key of ``config.yaml``.

``python -m ncd.pages.configdoc`` rewrites it; ``tests/test_readme.py`` checks it is up to date.
"""
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
SCHEMAS = ROOT / "workflow" / "schemas"
TARGET = ROOT / "config" / "README.md"
BOUNDS = (("minimum", "≥"), ("exclusiveMinimum", ">"), ("maximum", "≤"), ("exclusiveMaximum", "<"))


def _resolve(node, schema):
    while isinstance(node, dict) and "$ref" in node:
        ref = node["$ref"]
        target = schema
        for part in ref.lstrip("#/").split("/"):
            target = target[part]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def _kind(node):
    t = node.get("type", "")
    t = " or ".join(t) if isinstance(t, list) else t
    if "enum" in node:
        t = "one of " + ", ".join(f"`{v}`" for v in node["enum"])
    if t == "array" and isinstance(node.get("items"), dict) and "type" in node["items"]:
        t = f"array of {node['items']['type']}"
    bounds = ", ".join(f"{sym} {node[k]}" for k, sym in BOUNDS if k in node)
    return f"{t} ({bounds})" if bounds else t


def _rows(node, schema, prefix):
    node = _resolve(node, schema)
    for key, sub in (node.get("properties") or {}).items():
        sub = _resolve(sub, schema)
        path = f"{prefix}.{key}" if prefix else key
        required = key in node.get("required", [])
        desc = " ".join(str(sub.get("description", "")).split())
        default = f" Default: `{sub['default']}`." if "default" in sub else ""
        yield f"| `{path}` | {_kind(sub)} | {'yes' if required else 'no'} | {desc}{default} |"
        if sub.get("properties"):
            yield from _rows(sub, schema, path)


def render(schemas=SCHEMAS):
    top = yaml.safe_load((Path(schemas) / "config.schema.yaml").read_text())
    out = ["# config.yaml, section by section", "",
           "Generated from `workflow/schemas/*.schema.yaml` by `python -m ncd.pages.configdoc` (do not edit by hand;",
           "a test checks that it is up to date).  Every section is validated before any job runs; a",
           "misspelled key or an out-of-range value stops the run and names the section and key.", "",
           " ".join(str(top.get("description", "")).split()), ""]
    for section in top.get("properties", {}):
        path = Path(schemas) / f"{section}.schema.yaml"
        if not path.exists():
            continue
        schema = yaml.safe_load(path.read_text())
        out += [f"## `{section}`", ""]
        desc = " ".join(str(schema.get("description", "")).split())
        if desc:
            out += [desc, ""]
        out += ["| key | type | required | meaning |", "| --- | --- | --- | --- |", *_rows(schema, schema, ""), ""]
    return "\n".join(out).rstrip() + "\n"


if __name__ == "__main__":
    text = render()
    if sys.argv[1:] == ["--check"]:
        sys.exit(0 if TARGET.exists() and TARGET.read_text() == text else 1)
    TARGET.parent.mkdir(exist_ok=True)
    TARGET.write_text(text)
    print(f"wrote {TARGET}")
