"""pydantic's validation errors of a study file as one plain sentence per field.

Each error is named by its dotted path in the file as the user wrote it (an object of a list
by its name too), says what was expected and what was given (shortened, never a whole file),
and suggests the setting a misspelt key was meant to be, read from :func:`.study_model.json_schema`.
"""

from __future__ import annotations

import difflib
import functools

from pydantic import ValidationError

from .parameters import _describe
from .structures import FieldError, FieldErrors
from .study_model import json_schema

__all__: list[str] = []


def _path(data, loc) -> list:
    """The keys of ``loc`` that exist in the input (dropping pydantic's union tags and
    validator names), as a list of keys and list indices."""
    out, node = [], data
    for key in loc:
        if isinstance(node, dict) and key in node:
            node = node[key]
        elif isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node):
            node = node[key]
        else:
            continue
        out.append(key)
    return out


def _dotted(keys) -> str:
    text = ""
    for key in keys:
        text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else str(key))
    return text or "(top level)"


_BOUNDS = {
    "greater_than": ">",
    "greater_than_equal": ">=",
    "less_than": "<",
    "less_than_equal": "<=",
}


#: What a value of the wrong type must be, by pydantic error type.
_MUST_BE = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "an integer",
    "finite_number": "a finite number",
    "string_type": "a string",
    "tuple_type": "a list of two numbers",
    "bool_type": "true or false",
    "list_type": "a list",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "dict_type": "a table",
}


@functools.cache
def _schema() -> dict:
    """The JSON schema of study files, made once (it is fixed when the module is imported)."""
    return json_schema()


def _settings_at(loc) -> list[str]:
    """The settings of the table at the pydantic location ``loc`` (a union's tags included),
    read from the JSON schema of study files; [] where the path cannot be followed."""
    schema = _schema()

    def resolve(node):
        while "$ref" in node:
            node = schema["$defs"][node["$ref"].rsplit("/", 1)[-1]]
        return node

    node = resolve(schema)
    for key in loc:
        if key in node.get("properties", {}):
            node = resolve(node["properties"][key])
        elif key in node.get("discriminator", {}).get("mapping", {}):
            node = resolve({"$ref": node["discriminator"]["mapping"][key]})
        elif isinstance(key, int) and "items" in node:
            node = resolve(node["items"])
        else:
            return []
    tables = [resolve(n) for n in node.get("oneOf", node.get("anyOf", [node]))]
    return sorted({name for t in tables for name in t.get("properties", {})})


def _sentence(e: dict, keys: list) -> str:
    """One plain sentence for one pydantic error (``keys`` may be extended)."""
    kind, ctx, value = e["type"], e.get("ctx", {}), e.get("input")
    got = _describe(value)
    if kind == "missing":
        keys.append(e["loc"][-1])
        if tuple(e["loc"]) == ("sampler",):  # (a misspelt "objects" lands here too)
            return 'is required (unless [structure] kind = "objects")'
        return "is required"
    if kind == "extra_forbidden":
        close = difflib.get_close_matches(str(e["loc"][-1]), _settings_at(e["loc"][:-1]), 3)
        if close:
            return f"is not a setting here; did you mean {' or '.join(map(repr, close))}?"
        return "is not a setting here (a typo?); `rockstudy schema` lists the settings"
    if kind in _MUST_BE:
        return f"must be {_MUST_BE[kind]}, got {got}"
    if kind == "literal_error":
        return f"must be {ctx['expected']}, got {got}"
    if kind in _BOUNDS:
        bound = next(v for k, v in ctx.items() if k in ("gt", "ge", "lt", "le"))
        return f"must be {_BOUNDS[kind]} {bound}, got {got}"
    if kind == "too_short":
        return f"must hold at least {ctx['min_length']} item(s)"
    if kind == "string_too_short":
        return f"must hold at least {ctx['min_length']} character(s)"
    if kind == "union_tag_invalid":
        keys.append(ctx["discriminator"].strip("'"))
        return f"must be one of {ctx['expected_tags']}, got {_describe(ctx['tag'])}"
    if kind == "union_tag_not_found":
        keys.append(ctx["discriminator"].strip("'"))
        return "is required (it names the kind of table)"
    if kind == "value_error":
        error = ctx.get("error")
        if isinstance(error, FieldError):
            keys.extend(error.field.split("."))
        return str(error)
    return e["msg"]


def _object_name(data, keys) -> str:
    """`` ("Statue A")`` after a path into ``structure.objects[i]`` naming the object."""
    if len(keys) > 2 and keys[:2] == ["structure", "objects"] and isinstance(keys[2], int):
        item = data["structure"]["objects"][keys[2]]
        if isinstance(item, dict) and isinstance(item.get("name"), str):
            return f" ({item['name']!r})"
    return ""


def _expanded(errors):
    """pydantic's errors, with each :class:`FieldErrors` split into one error per field."""
    for e in errors:
        error = e.get("ctx", {}).get("error")
        if e["type"] == "value_error" and isinstance(error, FieldErrors):
            for one in error.errors:
                yield {**e, "ctx": {**e["ctx"], "error": one}}
        else:
            yield e


def _format_errors(err: ValidationError, data) -> list[str]:
    lines = []
    for e in _expanded(err.errors()):
        loc = e["loc"][:-1] if e["type"] == "missing" else e["loc"]
        keys = _path(data, loc)
        message = _sentence(e, keys)
        where = _dotted(keys)
        name = _object_name(data, keys)
        if name:  # after the index: structure.objects[1] ('Urn').width
            head = _dotted(keys[:3])
            where = head + name + where[len(head) :]
        line = f"{where}: {message}"
        if line not in lines:
            lines.append(line)
    return lines
