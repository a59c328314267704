#!/usr/bin/python3
"""Checks the layering of bendlab: every `#include "bendlab/<folder>/..."` in include/, src/ and
apps/ must go to a folder that the including file's folder may depend on (docs/design.md, Layout).

    core <- mesh <- geometry <- bending <- elasticity/membrane <- suspension <- capsule <- flow <- analysis <- apps
    parallel (MPI, optional) sits on flow, beside analysis; only apps include it.
    surfaces depends on core and mesh only; integrate on core, mesh and geometry.

The folder of a file is the first path component below include/bendlab/ or src/ (so flow/bim is
flow); everything under apps/ is "apps". Run by ctest; prints each offending file and edge and
exits with status 1 when there is any.
Usage: include_graph.py SOURCE_DIR | include_graph.py --self-test
"""
import pathlib
import re
import sys

# folder -> the folders its files may include (besides itself).
ALLOWED = {
    "core": set(),
    "mesh": {"core"},
    "geometry": {"core", "mesh"},
    "surfaces": {"core", "mesh"},
    "bending": {"core", "mesh", "geometry"},
    "elasticity": {"core", "mesh", "geometry"},
    "integrate": {"core", "mesh", "geometry"},
    "membrane": {"core", "mesh", "geometry", "bending", "elasticity"},
    # Many cells: vessels, contact forces, placement (no flow solver).
    "suspension": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane"},
    "capsule": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane", "integrate",
                "suspension"},
    "flow": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane", "integrate",
             "suspension", "capsule"},
    "analysis": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane", "integrate",
                 "suspension", "capsule", "flow"},
    # MPI domain decomposition of flow/lbm (built only with BENDLAB_MPI; nothing below includes it).
    "parallel": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane", "integrate",
                 "suspension", "capsule", "flow"},
    "apps": {"core", "mesh", "geometry", "surfaces", "bending", "elasticity", "membrane", "integrate",
             "suspension", "capsule", "flow", "analysis", "parallel"},
}

INCLUDE = re.compile(r'^\s*#\s*include\s*"bendlab/([^/"]+)/[^"]*"', re.MULTILINE)
SUFFIXES = {".hpp", ".cpp", ".h", ".cc", ".inl"}


def folder_of(root: pathlib.Path, path: pathlib.Path) -> str:
    rel = path.relative_to(root).parts
    if rel[0] == "apps":
        return "apps"
    if rel[0] == "include":
        return rel[2] if len(rel) > 3 else ""  # include/bendlab/<folder>/...
    return rel[1] if len(rel) > 2 else ""  # src/<folder>/...


def check(root: pathlib.Path) -> list[str]:
    problems = []
    for top in ("include", "src", "apps"):
        for path in sorted((root / top).rglob("*")):
            if path.suffix not in SUFFIXES or not path.is_file():
                continue
            rel = path.relative_to(root)
            src = folder_of(root, path)
            if src not in ALLOWED:
                problems.append(f"{rel}: folder '{src}' is not in the dependency table of tests/include_graph.py")
                continue
            for m in INCLUDE.finditer(path.read_text(encoding="utf-8", errors="replace")):
                dst = m.group(1)
                if dst == src:
                    continue
                if dst not in ALLOWED:
                    problems.append(f"{rel}: includes bendlab/{dst}/, a folder not in the dependency table")
                elif dst not in ALLOWED[src]:
                    problems.append(f"{rel}: forbidden edge {src} -> {dst} (#include \"bendlab/{dst}/...\"); "
                                    f"{src} may include only {', '.join(sorted(ALLOWED[src])) or 'itself'}")
    return problems


def self_test() -> int:
    """The check reports a reverse edge (mesh -> geometry) and accepts allowed ones."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        (root / "src/mesh").mkdir(parents=True)
        (root / "include/bendlab/geometry").mkdir(parents=True)
        (root / "apps/bendlab").mkdir(parents=True)
        (root / "src/mesh/bad.cpp").write_text('#include "bendlab/geometry/measures.hpp"\n')
        (root / "include/bendlab/geometry/ok.hpp").write_text('#include "bendlab/mesh/topology.hpp"\n')
        (root / "apps/bendlab/main.cpp").write_text('#include "bendlab/analysis/rbc_study.hpp"\n')
        problems = check(root)
    if len(problems) != 1 or "src/mesh/bad.cpp" not in problems[0] or "mesh -> geometry" not in problems[0]:
        print("include graph self-test failed:", problems)
        return 1
    print("include graph self-test: the reverse edge is reported:", problems[0])
    return 0


def main() -> int:
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    root = pathlib.Path(sys.argv[1]).resolve()
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"include graph: {len(problems)} forbidden include(s)")
        return 1
    print("include graph: every #include follows the layering")
    return 0


if __name__ == "__main__":
    sys.exit(main())
