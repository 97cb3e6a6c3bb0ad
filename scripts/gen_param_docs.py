#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Prints docs/parameters.md from libssao's own parameter table (ssao_param_info).

    /usr/bin/python3 scripts/gen_param_docs.py [--library build/lib/libssao.so] [--check FILE]

With --check, exits 1 if FILE differs from what the library describes (a ctest keeps the docs
true).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "blender_addon"))
import ssao_native  # noqa: E402

HEADER = """# Parameters

Generated from the library's parameter table (`ssao_param_info()`) by
`scripts/gen_param_docs.py`; a test fails when this file and the library disagree. Every
parameter is set by name through the C API (`ssao_job_set_int/float/string/floats`), on the
command line as `--name-with-dashes VALUE`, and (later) as a property of the Blender node.

"""

PARAMS_HEADER = """
| name | type | default | range / choices | unit | description |
|---|---|---|---|---|---|
"""

TYPES = {ssao_native.PARAM_INT: "int", ssao_native.PARAM_FLOAT: "float",
         ssao_native.PARAM_STRING: "choice", ssao_native.PARAM_FLOATS: "floats"}


def number(value):
    if value == float("inf"):
        return "inf"
    return f"{value:g}"


def render_variants(lib):
    """The variants (ssao_variant_info) and the parameters only each of them reads."""
    variants = ssao_native.variants(lib)
    lines = ["## Variants", "",
             "The `variant` parameter's choices (`ssao_variant_info()`). A count left at 0 "
             "(`samples`, `slices`, `steps`) takes the `quality` preset's value for the variant.",
             "", "| variant | reads | description |", "|---|---|---|"]
    for v in variants:
        reads = ", ".join(f"`{name}`" for name in v["parameters"])
        lines.append(f"| `{v['name']}` | {reads} | {v['description']} |")
    return "\n".join(lines) + "\n\n## All parameters\n"


def render(lib):
    rows = []
    for p in ssao_native.parameters(lib):
        if p["type"] == ssao_native.PARAM_STRING:
            default, span = f"`{p['default_string']}`", " \\| ".join(f"`{c}`" for c in p["choices"])
        elif p["type"] == ssao_native.PARAM_FLOATS:
            default, span = "identity", f"{p['count']} values"
        else:
            default = number(p["default"])
            span = f"{number(p['min'])} .. {number(p['max'])}"
        rows.append(f"| `{p['name']}` | {TYPES[p['type']]} | {default} | {span} | {p['unit']} "
                    f"| {p['description']} |")
    return HEADER + render_variants(lib) + PARAMS_HEADER + "\n".join(rows) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", default=None)
    parser.add_argument("--check", default=None, help="compare with this file instead of printing")
    args = parser.parse_args()
    text = render(ssao_native.load_library(args.library))
    if args.check:
        with open(args.check) as f:
            if f.read() != text:
                print(f"{args.check} is out of date: regenerate it with "
                      f"/usr/bin/python3 scripts/gen_param_docs.py > {args.check}", file=sys.stderr)
                return 1
        print(f"{args.check} matches the library's parameter table")
        return 0
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
