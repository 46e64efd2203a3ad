"""Checks of the workflow configuration (``config.yaml``) before any job is planned.

JSON schema alone lets through NaN and inf (they pass numeric bounds), floats such
as ``2000.0`` where an integer is meant, and relations between keys.  This module
adds, section by section (``workflow/rules/common.smk`` calls :func:`check_config`):

- every figure whose rules are loaded has its config section;
- every number anywhere in the config is finite;
- the section validates against ``workflow/schemas/<section>.schema.yaml``, with
  integers that are integers (``2000.0`` is refused where the schema says integer);
- cross-field constraints: ``<x>_min`` below ``<x>_max`` (``min_<x>``/``max_<x>``
  likewise), increasing ``*_range`` and ``segment`` pairs, ``shards`` at most ``runs``
  in a mapping holding both, and the few relations of :data:`RELATIONS`.

Every error is a :class:`ConfigError` (an :class:`ncd.InputError`) naming the section
and key path and the value, e.g. ``fig4_pile.ensemble.tol = nan: not a finite number``.
"""
import math
from pathlib import Path

import yaml

from ncd.core.errors import InputError


class ConfigError(InputError):
    """A configuration value or a missing section; the message names section and key."""


# (section, key path a, key path b, relation, text): config[section][a] <relation> config[section][b]
RELATIONS = [
    ("fig2_slope", ("flow", "step"), ("flow", "n_steps"), "<=", "the investigated step is one of the flow steps"),
    ("fig4_pile", ("tolerance_study", "runs"), ("ensemble", "runs"), "<=",
     "the tolerance study reruns members of the ensemble"),
    ("fig5_governing", ("flows", "scan_every"), ("flows", "duration"), "<=", "a flow is scanned at least once"),
    ("fig5_governing", ("uniform", "per_chain"), ("uniform", "max_per_chain"), "<=",
     "chains that do not agree grow from per_chain up to max_per_chain"),
]
# pairs named <x>_min/<x>_max whose bounds may coincide (a degenerate but valid range)
EQUAL_ALLOWED = ("radius",)


def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _name(path):
    return ".".join(str(p) for p in path)


def _fmt(value):
    return repr(value) if isinstance(value, str) else str(value)


def nonfinite(config, path=()):
    """Yield ``(path, value)`` of every NaN or infinite number in a nested config."""
    if isinstance(config, dict):
        for k, v in config.items():
            yield from nonfinite(v, path + (k,))
    elif isinstance(config, (list, tuple)):
        for i, v in enumerate(config):
            yield from nonfinite(v, path + (i,))
    elif isinstance(config, float) and not math.isfinite(config):
        yield path, config
    elif isinstance(config, int) and not isinstance(config, bool) and abs(config) > 1e308:
        yield path, f"an integer of {len(str(abs(config)))} digits"


def _validator(schema):
    """A draft 2020-12 validator whose ``integer`` refuses floats (2000.0) and whose
    ``number`` refuses NaN and inf."""
    from jsonschema import Draft202012Validator, validators

    checker = Draft202012Validator.TYPE_CHECKER.redefine_many({
        "integer": lambda _, x: isinstance(x, int) and not isinstance(x, bool),
        "number": lambda _, x: _is_number(x) and (abs(x) <= 1e308 if isinstance(x, int) else math.isfinite(x)),
    })
    cls = validators.extend(Draft202012Validator, type_checker=checker)
    return cls(schema)


def _schema_errors(section, data, schema_path, skip=()):
    """Schema violations of a section, except type errors at the paths ``skip``
    (non-finite numbers, reported once by :func:`nonfinite`)."""
    schema = yaml.safe_load(Path(schema_path).read_text())
    errors = sorted(_validator(schema).iter_errors(data), key=lambda e: [str(p) for p in e.absolute_path])
    out = []
    for e in errors:
        path = (section, *e.absolute_path)
        if path in skip and e.validator == "type":
            continue
        value = e.instance
        shown = _fmt(value) if not isinstance(value, (dict, list)) else "{...}" if isinstance(value, dict) else "[...]"
        out.append(f"{_name(path)} = {shown}: {e.message} (schema keyword '{e.validator}')")
    return out


def _pair_errors(node, path):
    """``<x>_min < <x>_max``, increasing ranges and ``shards <= runs`` in one mapping."""
    out = []
    for key, lo in node.items():
        if not isinstance(key, str) or not _is_number(lo):
            continue
        if "min" in key.split("_"):
            partner = "_".join("max" if p == "min" else p for p in key.split("_"))
            hi = node.get(partner)
            if _is_number(hi):
                base = key.replace("min", "").strip("_")
                bad = lo > hi if base in EQUAL_ALLOWED else lo >= hi
                if bad:
                    rel = "<=" if base in EQUAL_ALLOWED else "<"
                    out.append(f"{_name(path + (key,))} = {lo} must be {rel} {_name(path + (partner,))} = {hi}")
    for key, value in node.items():
        if isinstance(key, str) and (key.endswith("_range") or key == "segment") and isinstance(value, list) \
                and len(value) == 2 and all(_is_number(v) for v in value) and not value[0] < value[1]:
            out.append(f"{_name(path + (key,))} = {value}: the first bound must be below the second")
    shards, runs = node.get("shards"), node.get("runs")
    if _is_number(shards) and _is_number(runs) and shards > runs:
        out.append(f"{_name(path + ('shards',))} = {shards} must be <= {_name(path + ('runs',))} = {runs} "
                   "(a shard holds at least one run)")
    return out


def cross_field_errors(section, data, path=None):
    """Cross-field violations in config section ``section`` (a nested mapping)."""
    path = (section,) if path is None else path
    out = []
    if isinstance(data, dict):
        out += _pair_errors(data, path)
        for k, v in data.items():
            out += cross_field_errors(section, v, path + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out += cross_field_errors(section, v, path + (i,))
    if path == (section,):
        for sec, a, b, rel, why in RELATIONS:
            if sec != section:
                continue
            try:
                va, vb = _get(data, a), _get(data, b)
            except (KeyError, TypeError, IndexError):
                continue
            if _is_number(va) and _is_number(vb) and not (va <= vb if rel == "<=" else va < vb):
                out.append(f"{_name((section, *a))} = {va} must be {rel} {_name((section, *b))} = {vb} ({why})")
    return out


def _get(data, path):
    for p in path:
        data = data[p]
    return data


def check_config(config, sections, schema_dir):
    """Check ``config`` for the figures ``sections`` (each needs its config section and
    ``<schema_dir>/<section>.schema.yaml``); other sections present are checked too when
    they have a schema.  Raises :class:`ConfigError` listing every problem found."""
    if not isinstance(config, dict):
        raise ConfigError(f"the configuration must be a mapping of sections; got {type(config).__name__}")
    if not Path(schema_dir).is_dir():
        raise ConfigError(f"schema_dir = {str(schema_dir)!r} is not a directory of <section>.schema.yaml files")
    try:
        _check(config, sections, schema_dir)
    except RecursionError:
        raise ConfigError("the configuration nests too deeply (or refers to itself)") from None


def _check(config, sections, schema_dir):
    errors = []
    missing = [s for s in sections if s not in config]
    for s in missing:
        errors.append(f"config section '{s}' is missing: workflow/rules/{s}.smk needs it "
                      f"(add '{s}:' to config.yaml, or remove the rules file to drop the figure)")
    bad = dict(nonfinite(config))
    for path, value in bad.items():
        errors.append(f"{_name(path)} = {value}: not a finite number")
    for section in config:
        schema = Path(schema_dir) / f"{section}.schema.yaml"
        if not schema.exists():
            continue
        if not isinstance(config[section], dict):
            errors.append(f"config section '{section}' must be a mapping of keys; got {_fmt(config[section])}")
            continue
        errors += _schema_errors(section, config[section], schema, skip=bad)
        errors += cross_field_errors(section, config[section])
    if errors:
        raise ConfigError("invalid configuration:\n  " + "\n  ".join(errors))
