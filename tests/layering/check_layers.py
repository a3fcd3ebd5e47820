#!/usr/bin/env python3
"""Checks that every quoted #include under the layer folders points the way tests/layering/layers.txt allows, and
that no source listed in a kushner_host_only(...) call (cmake/host_only.cmake) includes a Kokkos header, directly or
through the repository's own headers.

Prints each offending include as `file:line: ...` (or chain) and exits 1; exits 0 when the tree follows both rules.
  check_layers.py [ROOT]          the tree at ROOT (default: the repository holding this script)
  check_layers.py --self-test     also shows that a wrong include and a host-only file reaching Kokkos are caught
"""
import os
import re
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
RULES = os.path.join(HERE, "layers.txt")
INCLUDE = re.compile(r'^\s*#\s*include\s+([<"])([^>"]+)[>"]')  # the bracket kind, the path
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
                        if not m or m.group(1) == "<":
                            continue
                        target = m.group(2)
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


def write_file(root, relpath, text, mode="w"):
    """Writes (or with mode "a" appends) text to root/relpath, making its folder: the self-tests' scratch trees."""
    path = os.path.join(root, relpath)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, mode) as f:
        f.write(text)


def self_test():
    """A scratch tree with one arrow the wrong way must be refused, and the same tree without it accepted."""
    with tempfile.TemporaryDirectory() as scratch:
        write_file(scratch, "core/math.hpp", "#pragma once\n")
        write_file(scratch, "engine/bank.hpp", '#include "core/math.hpp"\n')
        good = check(scratch)
        write_file(scratch, "kernels/step.hpp", '#include "core/math.hpp"\n#include "engine/bank.hpp"\n')
        bad = check(scratch)
    if good or len(bad) != 1 or not bad[0].startswith("kernels/step.hpp:2: kernels/ includes engine/bank.hpp"):
        print(f"self-test failed: clean tree gave {good}, wrong include gave {bad}")
        return False
    print(f"self-test: a wrong include is refused: {bad[0]}")
    return True


CALL = re.compile(r"kushner_host_only\(([^)]*)\)")
KOKKOS = re.compile(r"^(impl/)?Kokkos")


def listed_sources(root):
    """(CMakeLists.txt, path) of every literal file named in a kushner_host_only call."""
    for dirpath, dirnames, files in os.walk(root):
        dirnames[:] = [d for d in dirnames if not d.startswith((".", "build"))]
        if "CMakeLists.txt" not in files:
            continue
        cmake = os.path.join(dirpath, "CMakeLists.txt")
        with open(cmake) as f:
            text = re.sub(r"#[^\n]*", "", f.read())
        for call in CALL.finditer(text):
            for name in call.group(1).split():
                if "${" not in name:  # generated files include nothing of ours
                    yield cmake, os.path.join(dirpath, name)


def kokkos_chain(path, root, seen):
    """The include chain from path to a Kokkos header, or None."""
    if path in seen:
        return None
    seen.add(path)
    with open(path, encoding="utf-8", errors="replace") as f:
        includes = [m.groups() for m in map(INCLUDE.match, f) if m]
    for kind, target in includes:
        if kind == "<":
            if KOKKOS.match(target):
                return [target]
            continue
        for candidate in (os.path.join(root, target), os.path.join(os.path.dirname(path), target)):
            if os.path.exists(candidate):
                rest = kokkos_chain(candidate, root, seen)
                if rest:
                    return [os.path.relpath(candidate, root)] + rest
                break
    return None


def check_host_only(root, listed):
    """Sources named in a kushner_host_only(...) call (cmake/host_only.cmake) that reach a Kokkos header: CUDA builds
    give them to the host compiler alone, where Kokkos' CUDA headers stop with an #error, and CI's compile check
    does not compile them at all, so without this a listed file that came to include Kokkos would first fail on the
    GPU machine."""
    problems = []
    for cmake, source in listed:
        if not os.path.exists(source):
            problems.append(f"{os.path.relpath(cmake, root)}: kushner_host_only names {os.path.relpath(source, root)}, "
                            f"which does not exist")
            continue
        chain = kokkos_chain(source, root, set())
        if chain:
            problems.append(f"{os.path.relpath(source, root)} is host-only ({os.path.relpath(cmake, root)}) but "
                            f"includes Kokkos: {' -> '.join(chain)}")
    return problems


def self_test_host_only():
    """A listed file that reaches Kokkos through a header of ours must be refused; without that include, accepted."""
    with tempfile.TemporaryDirectory() as scratch:
        write_file(scratch, "engine/CMakeLists.txt", "kushner_host_only(plain.cpp)  # no Kokkos\n")
        write_file(scratch, "engine/space.hpp", "#pragma once\n#include <Kokkos_Core.hpp>\n")
        write_file(scratch, "engine/plain.cpp", "#include <vector>\n")
        good = check_host_only(scratch, list(listed_sources(scratch)))
        write_file(scratch, "engine/plain.cpp", '#include "engine/space.hpp"\n', mode="a")
        bad = check_host_only(scratch, list(listed_sources(scratch)))
    if good or len(bad) != 1 or "engine/space.hpp -> Kokkos_Core.hpp" not in bad[0]:
        print(f"self-test failed: clean host-only tree gave {good}, Kokkos through a header gave {bad}")
        return False
    print(f"self-test: a host-only file reaching Kokkos is refused: {bad[0]}")
    return True


def main(argv):
    args = [a for a in argv[1:] if a != "--self-test"]
    root = os.path.abspath(args[0]) if args else os.path.dirname(os.path.dirname(HERE))
    ok = (self_test() and self_test_host_only()) if "--self-test" in argv else True
    host_only = list(listed_sources(root))
    problems = check(root) + check_host_only(root, host_only)
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include(s) point the wrong way (tests/layering/layers.txt, cmake/host_only.cmake)")
        return 1
    print(f"layers: every include under {root} points the way tests/layering/layers.txt allows; none of the "
          f"{len(host_only)} host-only sources includes Kokkos")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
