#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Fails when the `ssao --help` text quoted in docs/cli.md differs from the tool's.

    /usr/bin/python3 tests/docs/check_cli_help.py SSAO_BINARY docs/cli.md
"""
import subprocess
import sys


def main():
    binary, doc = sys.argv[1], sys.argv[2]
    actual = subprocess.run([binary, "--help"], check=True, capture_output=True,
                            text=True).stdout
    with open(doc) as f:
        text = f.read()
    marker = "## `ssao --help`\n\n```\n"
    start = text.find(marker)
    if start < 0:
        print(f"{doc}: no '## `ssao --help`' section", file=sys.stderr)
        return 1
    start += len(marker)
    quoted = text[start:text.index("```", start)]
    if quoted != actual:
        print(f"{doc} quotes an outdated --help; update the block with the output of "
              f"`{binary} --help`", file=sys.stderr)
        return 1
    print(f"{doc} quotes the current --help")
    return 0


if __name__ == "__main__":
    sys.exit(main())
