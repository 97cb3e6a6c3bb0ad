#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Blender add-on keeps what it remembers between events in one object (session.py): no
other module of blender_addon/ has state of its own. Read from the source (no Blender):
  - no `global` statement outside session.py;
  - no module-level empty list, dict or set (the start of a table filled later), and no
    module-level table changed by a function (an item set, or append/update/pop/...);
  - no assignment to another add-on module's attribute (`compute.preferred_export_dir = ...`).

    /usr/bin/python3 tests/python/test_addon_state.py [ADDON_DIR]
"""
import ast
import os
import sys
import unittest

ADDON = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender_addon")
SESSION = "session.py"


def state_outside_session(folder):
    """["file:line: what"] for each piece of module state outside session.py."""
    found = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".py") or name == SESSION:
            continue
        with open(os.path.join(folder, name), encoding="utf-8") as f:
            tree = ast.parse(f.read(), name)
        siblings = {alias.asname or alias.name for node in ast.walk(tree)
                    if isinstance(node, ast.ImportFrom) and node.level == 1 and not node.module
                    for alias in node.names}
        for node in ast.walk(tree):
            if isinstance(node, ast.Global):
                found.append(f"{name}:{node.lineno}: global {', '.join(node.names)}")
            elif isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    if isinstance(target, ast.Attribute) and \
                            isinstance(target.value, ast.Name) and target.value.id in siblings:
                        found.append(f"{name}:{node.lineno}: sets {target.value.id}."
                                     f"{target.attr}")
        module_names = set()
        for node in tree.body:
            if isinstance(node, ast.Assign):
                module_names.update(t.id for t in node.targets if isinstance(t, ast.Name))
                if _empty_container(node.value):
                    names = ", ".join(ast.unparse(t) for t in node.targets)
                    found.append(f"{name}:{node.lineno}: module-level table {names}")
        for function in ast.walk(tree):
            if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found += [f"{name}:{line}: changes {table}"
                          for line, table in _tables_changed(function, module_names)]
    return found


MUTATORS = {"append", "extend", "insert", "update", "pop", "popitem", "clear", "add",
            "discard", "remove", "setdefault"}


def _tables_changed(function, module_names):
    """(line, name) where `function` changes a module-level table in place."""
    for node in ast.walk(function):
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, ast.AugAssign) else \
            node.targets if isinstance(node, ast.Delete) else []
        for target in targets:
            if isinstance(target, ast.Subscript) and isinstance(target.value, ast.Name) and \
                    target.value.id in module_names:
                yield node.lineno, target.value.id
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and \
                node.func.attr in MUTATORS and isinstance(node.func.value, ast.Name) and \
                node.func.value.id in module_names:
            yield node.lineno, node.func.value.id


def _empty_container(value):
    if isinstance(value, (ast.List, ast.Set)) and not value.elts:
        return True
    if isinstance(value, ast.Dict) and not value.keys:
        return True
    return isinstance(value, ast.Call) and isinstance(value.func, ast.Name) and \
        value.func.id in ("list", "dict", "set") and not value.args and not value.keywords


class AddonStateTest(unittest.TestCase):
    def test_only_the_session_holds_state(self):
        self.assertEqual(state_outside_session(ADDON), [])

    def test_the_check_sees_each_kind_of_state(self):
        # The check itself: a module with each kind is reported, line by line.
        import tempfile
        with tempfile.TemporaryDirectory() as folder:
            with open(os.path.join(folder, "events.py"), "w") as f:
                f.write("from . import compute\n_frames = []\n_seen = set()\nFIXED = {'a': 1}\n"
                        "def f():\n    global _started\n    compute.export_dir = 'x'\n"
                        "    FIXED['a'] += 1\n    FIXED.update(b=2)\n    return FIXED['a']\n")
            self.assertEqual(state_outside_session(folder),
                             ["events.py:6: global _started", "events.py:7: sets compute."
                              "export_dir", "events.py:2: module-level table _frames",
                              "events.py:3: module-level table _seen",
                              "events.py:8: changes FIXED", "events.py:9: changes FIXED"])


if __name__ == "__main__":
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        ADDON = sys.argv.pop(1)
    unittest.main()
