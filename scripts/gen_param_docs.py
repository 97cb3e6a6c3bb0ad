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

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "python"))
import ssao  # noqa: E402

HEADER = """# Parameters

Generated from the library's parameter table (`ssao_param_info()`) by
`scripts/gen_param_docs.py`; a test fails when this file and the library disagree. Every
parameter is set by name through the C API (`ssao_job_set_int/float/string/floats`), on the
command line as `--name-with-dashes VALUE`, and (later) as a property of the Blender node.

"""

PARAMS_HEADER = """
Each parameter belongs to a group (`ssao_param_group()`): `ao` (what the estimate computes),
`quality` (how much work it does), `shaping` (the final look), `input` (how the passes are to be
read), `camera` (the camera they were rendered with: `projection` chooses Blender's lens and
sensor, pinhole `intrinsics` or a `projection_matrix`; see [conventions.md](conventions.md)) and
`execution`. Front ends select by group: the Blender node shows `ao`, `quality` and `shaping`.

| name | group | type | default | range / choices | unit | description |
|---|---|---|---|---|---|---|
"""

FOOTER = """
## The automatic radius

`radius` defaults to 1 scene unit in the library, which suits no scene in particular. The
front ends choose one when the user gives none, by the library's rule
`ssao_job_choose_radius()` (the CLI, `povray-ssao` and the Python module all call it): the
camera file's `ao_distance`, else the automatic radius `ssao_job_auto_radius()`: **10% of the
view's width (along the image's larger side) at the median depth of the geometry pixels**;
orthographic: 10% of the view's width. The tools print the radius and the flag that changes it.

The 10% is the geometric mean over scenes whose AO distance an artist chose: the six benchmark
scenes and the three development scenes (`/usr/bin/python3 benchmarks/radius_calibration.py`
prints the benchmark's from `build/benchmark_kit`; the development scenes are not shipped):

| scene | AO distance | median depth | view width there | ratio |
|---|--:|--:|--:|--:|
| cavity | 0.50 | 4.86 | 5.00 | 0.100 |
| contact | 0.80 | 5.96 | 6.13 | 0.130 |
| depth_range | 1.00 | 7.48 | 7.69 | 0.130 |
| heavy | 0.80 | 5.50 | 5.66 | 0.141 |
| ortho | 0.60 | 9.03 | 7.50 | 0.080 |
| thin | 0.50 | 5.33 | 5.48 | 0.091 |
| crates (development) | 0.80 | 8.67 | 8.92 | 0.090 |
| shelf (development) | 0.50 | 6.76 | 8.11 | 0.062 |
| arches (development) | 1.00 | 8.72 | 9.81 | 0.102 |

Geometric mean 0.100 (median 0.100, range 0.062 to 0.141). The rule follows the framing, not
the resolution: the same shot at another size gets the same radius. What it gives on POV-Ray's
example scenes is in [povray.md](povray.md#the-default-radius).
"""

TYPES = {ssao.PARAM_INT: "int", ssao.PARAM_FLOAT: "float",
         ssao.PARAM_STRING: "choice", ssao.PARAM_FLOATS: "floats"}


def number(value):
    if value == float("inf"):
        return "inf"
    return f"{value:g}"


def render_variants(lib):
    """The variants (ssao_variant_info) and the parameters only each of them reads."""
    variants = ssao.variants(lib)
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
    for p in ssao.parameters(lib):
        if p["type"] == ssao.PARAM_STRING:
            default, span = f"`{p['default_string']}`", " \\| ".join(f"`{c}`" for c in p["choices"])
        elif p["type"] == ssao.PARAM_FLOATS:
            default = "identity" if p["count"] == 16 else "unset (zeros)"
            span = f"{p['count']} values"
        else:
            default = number(p["default"])
            span = f"{number(p['min'])} .. {number(p['max'])}"
        rows.append(f"| `{p['name']}` | {p['group']} | {TYPES[p['type']]} | {default} | {span} | {p['unit']} "
                    f"| {p['description']} |")
    return HEADER + render_variants(lib) + PARAMS_HEADER + "\n".join(rows) + "\n" + FOOTER


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", default=None)
    parser.add_argument("--check", default=None, help="compare with this file instead of printing")
    args = parser.parse_args()
    text = render(ssao.load_library(args.library))
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
