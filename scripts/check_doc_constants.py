#!/usr/bin/env python3
"""Check the few constants the docs quote against the code.

Usage: check_doc_constants.py [ROOT]

Each entry of CHECKS names a constant, where the code sets it (file and a
regular expression whose group 1 is the value) and where a doc quotes it (the
same). The value is read from both and compared as a number; a doc may write
"half" for 0.5. Exit status 0 when every pair agrees, 1 when one differs or a
pattern finds nothing (a moved constant or reworded doc line is a failure
too: update the entry then), naming the doc line and the code line.

Keep the list small: the margins, defaults and limits a user reads in the docs.
"""
import pathlib
import re
import sys

# (constant, code file, code pattern, doc file, doc pattern)
CHECKS = [
    ("kReserveMargin",
     "src/core/world.cpp", r"constexpr double kReserveMargin = ([0-9.]+);",
     "docs/architecture.md", r"with a margin of ([0-9.]+) \(`kReserveMargin`"),
    ("kReserveMargin (error_vs_runtime.md)",
     "src/core/world.cpp", r"constexpr double kReserveMargin = ([0-9.]+);",
     "docs/error_vs_runtime.md", r"kept with a margin of ([0-9.]+) \(`kReserveDecay`, `kReserveMargin`"),
    ("kReserveDecay",
     "src/core/world.cpp", r"constexpr double kReserveDecay = ([0-9.]+);",
     "docs/architecture.md", r"decaying by a factor of ([0-9.]+) a tick \(`kReserveDecay`"),
    ("Physics::kFrontierTolerance",
     "src/core/physics.hpp", r"static constexpr double kFrontierTolerance = ([0-9.]+);",
     "docs/response.md", r"more than (half|[0-9.]+) (?:of )?the smaller leaf\s+radius \(`Physics::kFrontierTolerance`"),
    ("ResponseOptions::solver_task_manifolds",
     "include/sphere_tree_collision/response_options.hpp", r"int solver_task_manifolds = ([0-9]+);",
     "docs/parallel.md", r"`ResponseOptions::solver_task_manifolds` \(([0-9]+)\)"),
    ("kMaxSweepRounds",
     "src/core/continuous.hpp", r"constexpr std::size_t kMaxSweepRounds = ([0-9]+);",
     "docs/response.md", r"`kMaxSweepRounds` \(([0-9]+)\)"),
    ("~rate default (node)",
     "src/ros/include/sphere_tree_collision/ros/node_params.hpp", r"double rate = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~rate` \| ([0-9.]+) \|"),
    ("rate default (world.launch)",
     "launch/world.launch", r'<arg name="rate" default="([0-9.]+)"',
     "docs/ros_interface.md", r"^\| `~rate` \| ([0-9.]+) \|"),
    ("~tick_budget default (node)",
     "src/ros/include/sphere_tree_collision/ros/node_params.hpp", r"double tick_budget_ms = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~tick_budget` \| ([0-9.]+) \|"),
    ("tick_budget default (world.launch)",
     "launch/world.launch", r'<arg name="tick_budget" default="([0-9.]+)"',
     "docs/ros_interface.md", r"^\| `~tick_budget` \| ([0-9.]+) \|"),
    ("~detection_budget default (node)",
     "src/ros/include/sphere_tree_collision/ros/node_params.hpp", r"double detection_budget_ms = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~detection_budget` \| ([0-9.]+) \|"),
    ("detection_budget default (world.launch)",
     "launch/world.launch", r'<arg name="detection_budget" default="([0-9.]+)"',
     "docs/ros_interface.md", r"^\| `~detection_budget` \| ([0-9.]+) \|"),
    ("~gaze_timeout default (node)",
     "src/ros/include/sphere_tree_collision/ros/node_params.hpp", r"double gaze_timeout = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~gaze_timeout` \| ([0-9.]+) \|"),
    ("~gaze_timeout in the README's tour",
     "src/ros/include/sphere_tree_collision/ros/node_params.hpp", r"double gaze_timeout = ([0-9.]+);",
     "README.md", r"`~gaze_timeout`, ([0-9.]+) s"),
    ("~solver_iterations default",
     "include/sphere_tree_collision/response_options.hpp", r"int iterations = ([0-9]+);",
     "docs/ros_interface.md", r"^\| `~solver_iterations` \| ([0-9]+) \|"),
    ("ResponseOptions::iterations (bullet.md)",
     "include/sphere_tree_collision/response_options.hpp", r"int iterations = ([0-9]+);",
     "docs/bullet.md", r"`WorldConfig` defaults \(([0-9]+) iterations"),
    ("ResponseOptions::iterations (response.md)",
     "include/sphere_tree_collision/response_options.hpp", r"int iterations = ([0-9]+);",
     "docs/response.md", r"Why ([0-9]+) iterations \(`ResponseOptions::iterations`\)"),
    ("kSoftCollisionPasses",
     "src/core/contact_solver_soft.cpp", r"constexpr int kSoftCollisionPasses = ([0-9]+);",
     "docs/response.md", r"`kSoftCollisionPasses` \(([0-9]+)\) passes each"),
    ("solver_iterations default (World.cfg, live tuning)",
     "cfg/World.cfg", r'"solver_iterations", int_t, 0, "[^"]*", ([0-9]+)\)',
     "docs/ros_interface.md", r"^\| `~solver_iterations` \| ([0-9]+) \|"),
    ("~max_entities default",
     "include/sphere_tree_collision/world.hpp", r"std::size_t max_entities = ([0-9]+);",
     "docs/ros_interface.md", r"^\| `~max_entities` \| ([0-9]+) \|"),
    ("~max_speed default",
     "include/sphere_tree_collision/limits.hpp", r"double max_speed = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~max_speed` \| ([0-9.]+) \|"),
    ("~world_extent default",
     "include/sphere_tree_collision/limits.hpp", r"double world_extent = ([0-9.]+);",
     "docs/ros_interface.md", r"^\| `~world_extent` \| ([0-9.]+) \|"),
    ("~max_mesh_vertices default",
     "include/sphere_tree_collision/limits.hpp", r"max_mesh_vertices = ([0-9']+);",
     "docs/ros_interface.md", r"^\| `~max_mesh_bytes`, `~max_mesh_vertices`, `~max_mesh_triangles` \| [^,]+, ([0-9]+), [0-9]+ \|"),
    ("~max_mesh_triangles default",
     "include/sphere_tree_collision/limits.hpp", r"max_mesh_triangles = ([0-9']+);",
     "docs/ros_interface.md", r"^\| `~max_mesh_bytes`, `~max_mesh_vertices`, `~max_mesh_triangles` \| [^,]+, [0-9]+, ([0-9]+) \|"),
    ("sleeping.time_to_sleep",
     "include/sphere_tree_collision/phase_options.hpp", r"double time_to_sleep = ([0-9.]+);",
     "docs/sleeping.md", r"`sleeping\.time_to_sleep` \(([0-9.]+) s\)"),
]

WORDS = {"half": 0.5}


def find(root, path, pattern):
    """(value, line number, line) of the first match, or None. A space in the
    pattern matches any run of white space, line breaks included, so a
    reflowed doc line still matches."""
    text = (root / path).read_text(encoding="utf-8")
    match = re.search(pattern.replace(" ", r"\s+"), text, re.MULTILINE)
    if not match:
        return None
    raw = match.group(1)
    value = WORDS.get(raw)
    if value is None:
        value = float(raw.replace("'", ""))  # C++ digit separators
    line_no = text.count("\n", 0, match.start(1)) + 1
    line = text.splitlines()[line_no - 1].strip()
    return value, line_no, line


def main(argv):
    root = pathlib.Path(argv[0]) if argv else pathlib.Path(__file__).resolve().parent.parent
    failed = 0
    for name, code_path, code_pattern, doc_path, doc_pattern in CHECKS:
        code = find(root, code_path, code_pattern)
        doc = find(root, doc_path, doc_pattern)
        if code is None or doc is None:
            failed += 1
            where = f"{code_path} /{code_pattern}/" if code is None else f"{doc_path} /{doc_pattern}/"
            print(f"FAIL {name}: not found in {where}")
            continue
        if abs(code[0] - doc[0]) > 1e-12 * max(1.0, abs(code[0])):
            failed += 1
            print(f"FAIL {name}: the doc says {doc[0]:g}, the code {code[0]:g}")
            print(f"  doc  {doc_path}:{doc[1]}: {doc[2]}")
            print(f"  code {code_path}:{code[1]}: {code[2]}")
        else:
            print(f"ok   {name} = {code[0]:g} ({doc_path}:{doc[1]}, {code_path}:{code[1]})")
    print(f"check_doc_constants: {len(CHECKS)} constants, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
