#!/usr/bin/env python3
"""Checks that every quoted #include under the layer folders points the way tests/layering/layers.txt allows.

Prints each offending include as `file:line: ...` and exits 1; exits 0 when the tree follows the layers.
  check_layers.py [ROOT]          the tree at ROOT (default: the repository holding this script)
  check_layers.py --self-test     also shows that a wrong include in a scratch tree is caught
"""
import os
import re
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
RULES = os.path.join(HERE, "layers.txt")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SOURCES = (".hpp", ".cpp", ".h", ".cu", ".in")


def read_rules(path):
    allowed, generated = {}, {}
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            head, _, tail = line.partition(":")
            head = head.strip()
            if head.startswith("generated "):
                generated[head.split(None, 1)[1]] = set(tail.split())
            elif head:
                allowed[head] = set(tail.split())
            else:
                sys.exit(f"{path}:{number}: no folder before ':'")
    return allowed, generated


def layer_of(relpath, allowed):
    """The longest rule folder holding relpath, or None."""
    best = None
    for folder in allowed:
        if relpath.startswith(folder + "/") and (best is None or len(folder) > len(best)):
            best = folder
    return best


def top_layer(folder):
    return folder.split("/", 1)[0]


def check(root):
    allowed, generated = read_rules(RULES)
    layers = {top_layer(f) for f in allowed}
    problems = []
    for folder in sorted({top_layer(f) for f in allowed}):
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for name in sorted(files):
                if not name.endswith(SOURCES):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root).replace(os.sep, "/")
                layer = layer_of(rel, allowed)
                if layer is None:
                    continue
                may = allowed[layer] | {top_layer(layer)} | ({layer} if "/" in layer else set())
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        first = target.split("/", 1)[0]
                        if target in generated:
                            if top_layer(layer) not in generated[target]:
                                problems.append(f"{rel}:{number}: includes generated {target}, which only "
                                                f"{', '.join(sorted(generated[target]))} may include")
                        elif first in layers:
                            if first not in may and not any(target.startswith(l + "/") for l in may if "/" in l):
                                problems.append(f"{rel}:{number}: {layer}/ includes {target}: {layer} may include "
                                                f"only {', '.join(sorted(allowed[layer])) or 'itself'}")
                        elif not os.path.exists(os.path.join(dirpath, target)):
                            problems.append(f"{rel}:{number}: includes {target}, which is neither in a layer "
                                            f"folder nor beside the file")
    return problems


def self_test():
    """A scratch tree with one arrow the wrong way must be refused, and the same tree without it accepted."""
    with tempfile.TemporaryDirectory() as scratch:
        for folder in ("core", "kernels", "engine"):
            os.makedirs(os.path.join(scratch, folder))
        with open(os.path.join(scratch, "core", "math.hpp"), "w") as f:
            f.write("#pragma once\n")
        with open(os.path.join(scratch, "engine", "bank.hpp"), "w") as f:
            f.write('#include "core/math.hpp"\n')
        good = check(scratch)
        with open(os.path.join(scratch, "kernels", "step.hpp"), "w") as f:
            f.write('#include "core/math.hpp"\n#include "engine/bank.hpp"\n')
        bad = check(scratch)
    if good or len(bad) != 1 or not bad[0].startswith("kernels/step.hpp:2: kernels/ includes engine/bank.hpp"):
        print(f"self-test failed: clean tree gave {good}, wrong include gave {bad}")
        return False
    print(f"self-test: a wrong include is refused: {bad[0]}")
    return True


def main(argv):
    args = [a for a in argv[1:] if a != "--self-test"]
    root = os.path.abspath(args[0]) if args else os.path.dirname(os.path.dirname(HERE))
    ok = self_test() if "--self-test" in argv else True
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include(s) point the wrong way (tests/layering/layers.txt)")
        return 1
    print(f"layers: every include under {root} points the way tests/layering/layers.txt allows")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
