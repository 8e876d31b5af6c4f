"""Generator of the bad-input corpus: robot YAMLs, task YAMLs, URDFs and command lines.

Every case is derived from a shipped, valid file by one mutation, with the outcome it must
have: exit 0, or exit 2 with a ``FILE:LINE[:COL]: FIELD: ...`` line naming ``field``. Random
choices (which numbers become booleans, which keys get a typo) come from ``random.Random(SEED)``,
so the corpus is the same on every run. ``python tests/_corpus.py OUT`` writes it out to look at.
"""

from __future__ import annotations

import copy
import random
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pybullet_data
import yaml

from robocfg.config.load import format_loc

ROOT = Path(__file__).resolve().parent.parent
TASKS = ROOT / "robocfg" / "data" / "tasks"
ROBOTS = ROOT / "robocfg" / "data" / "robots"
SEED = 14
BOOLS_PER_TASK = 8
TYPOS_PER_TASK = 5
PANDA_URDF = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"


@dataclass
class Case:
    """One corpus entry: files to write (relative path → text), the command line (``{dir}`` is
    the folder they are written to), the exit code it must give and, for exit 2, the file and
    field path a ``FILE:LINE`` line must name (``field`` None: a file-level problem; ``file``
    None: a command-line error, ``expect`` is then a fragment of the message)."""

    name: str
    files: dict[str, str]
    args: list[str]
    exit: int
    file: str | None = None
    field: str | None = None
    expect: str = ""
    subprocess: bool = False


def _dump(data: dict) -> str:
    return yaml.safe_dump(data, sort_keys=False)


def _leaves(data, prefix=()) -> Iterator[tuple[tuple, object]]:
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _leaves(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _leaves(v, (*prefix, i))
    else:
        yield prefix, data


def _keys(data, prefix=()) -> Iterator[tuple]:
    if isinstance(data, dict):
        for k, v in data.items():
            yield (*prefix, k)
            yield from _keys(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _keys(v, (*prefix, i))


def _set(data: dict, path: tuple, value) -> dict:
    out = copy.deepcopy(data)
    cur = out
    for part in path[:-1]:
        cur = cur[part]
    cur[path[-1]] = value
    return out


def _rename(data: dict, path: tuple, new: str) -> dict:
    out = copy.deepcopy(data)
    cur = out
    for part in path[:-1]:
        cur = cur[part]
    cur[new] = cur.pop(path[-1])
    return out


def _task(name: str) -> dict:
    return yaml.safe_load((TASKS / f"{name}.yaml").read_text())


def _validate(fname: str, data_or_text, exit_: int, field_: str | None = None, name: str = "", expect: str = "") -> Case:
    text = data_or_text if isinstance(data_or_text, str) else _dump(data_or_text)
    return Case(name or fname, {fname: text}, ["validate", "{dir}/" + fname], exit_, fname if exit_ else None, field_, expect)


def _typo_expect(path: tuple) -> str:
    """A misspelt schema key is an unknown key; a misspelt name used as a key (a joint in a
    waypoint map, a robot in ``variants``) gets a suggestion."""
    if (path[:2] == ("trajectory", "waypoints") and len(path) == 4) or (path[:1] == ("variants",) and len(path) == 2):
        return "did you mean"
    return "unknown key"


def task_cases(rng: random.Random) -> list[Case]:
    cases = []
    for path in sorted(TASKS.glob("*.yaml")):
        base = yaml.safe_load(path.read_text())
        stem = path.stem
        cases.append(_validate(f"{stem}.yaml", path.read_text(), 0, name=f"task-valid-{stem}"))
        numbers = [p for p, v in _leaves(base) if isinstance(v, (int, float)) and not isinstance(v, bool)]
        for p in rng.sample(numbers, min(BOOLS_PER_TASK, len(numbers))):
            cases.append(_validate(f"{stem}-bool-{format_loc(p)}.yaml", _set(base, p, True), 2, format_loc(p),
                                   name=f"task-bool-{stem}-{format_loc(p)}"))
        keys = [p for p in _keys(base) if isinstance(p[-1], str) and p[-1] not in ("task",)]
        for p in rng.sample(keys, min(TYPOS_PER_TASK, len(keys))):
            typo = p[-1][:-1] + p[-1][-1].upper() + "x"
            cases.append(_validate(f"{stem}-typo-{format_loc(p)}.yaml", _rename(base, p, typo), 2,
                                   format_loc((*p[:-1], typo)), name=f"task-typo-{stem}-{format_loc(p)}",
                                   expect=_typo_expect(p)))
    return cases


def specific_task_cases() -> list[Case]:
    """The checks that once passed validate and failed only in run (each needs no simulation)."""
    gr, tr, pp, gs, ft = _task("gripper"), _task("trajectory"), _task("pick_place"), _task("grasp"), _task("follow_target")
    cube = gr["scene"]["objects"][0]
    c = []

    def v(name, data, field_, expect=""):
        c.append(_validate(f"{name}.yaml", data, 2, field_, name=name, expect=expect))

    v("hold-object-typo", _set(gr, ("gripper", "hold_object"), "cub"), "gripper.hold_object", "did you mean 'cube'")
    v("hold-object-obstacle", _set(gr, ("gripper", "hold_object"), "wall"), "gripper.hold_object", "no object 'wall'")
    v("hold-object-empty-scene", _set(gr, ("scene", "objects"), []), "gripper.hold_object", "known: none")
    v("gripper-cycles-bool", _set(gr, ("gripper", "cycles"), True), "gripper.cycles")
    v("gripper-rate-string", _set(gr, ("gripper", "rate"), "2.0"), "gripper.rate")
    v("wp-unknown-joint", _set(tr, ("trajectory", "waypoints"), ["home", {"panda_joint9": 0.1}]),
      "trajectory.waypoints[1].panda_joint9", "did you mean")
    v("wp-wrong-length", _set(tr, ("trajectory", "waypoints"), ["home", [0.0, 0.1, 0.2]]),
      "trajectory.waypoints[1]", "3 values for 7 arm joints")
    v("wp-outside-limits", _set(tr, ("trajectory", "waypoints"), ["home", [0, -0.5, 0, -4.0, 0, 1.5, 0.8]]),
      "trajectory.waypoints[1][3]", "outside its limits")
    v("wp-map-outside-limits", _set(tr, ("trajectory", "waypoints"), [{"panda_joint1": 3.5}]),
      "trajectory.waypoints[0].panda_joint1", "outside its limits")
    v("wp-unknown-name", _set(tr, ("trajectory", "waypoints"), ["hom"]), "trajectory.waypoints[0]", "did you mean 'home'")
    v("wp-bool-value", _set(tr, ("trajectory", "waypoints"), ["home", [0, True, 0, -2, 0, 1.5, 0.8]]), "trajectory.waypoints[1]")
    v("trajectory-unknown-arm", _set(tr, ("trajectory", "arm"), "lefty"), "trajectory.arm", "no arm 'lefty'")
    dup = copy.deepcopy(cube)
    v("duplicate-scene-object", _set(gr, ("scene", "objects"), [cube, dup]), "scene.objects[1].name", "used twice")
    v("duplicate-grasp-objects", _set(gs, ("grasp", "objects"), [gs["grasp"]["objects"][0]] * 2),
      "grasp.objects[1].name", "used twice")
    v("pick-object-named-like-scene", _set(_set(pp, ("scene", "objects"), [dict(cube, name=pp["pick_place"]["object"]["name"])]),
                                           ("scene", "ground"), True), "pick_place.object.name", "already used")
    v("grasp-no-objects", _set(gs, ("grasp", "objects"), []), "grasp.objects", "no objects to grasp")
    v("grasp-mesh-missing", _set(gs, ("grasp", "objects", 0), {"name": "m", "shape": "mesh", "mesh": "nope.obj", "size": [1, 1, 1]}),
      "grasp.objects[0].mesh", "not found")
    v("scene-mesh-missing", _set(gr, ("scene", "objects"), [cube, {"name": "duck", "shape": "mesh", "mesh": "pybullet_data://no_duck.urdf",
                                                                   "size": [1, 1, 1]}]), "scene.objects[1].mesh", "not found")
    v("pick-mesh-missing", _set(pp, ("pick_place", "object"), {"name": "m", "shape": "mesh", "mesh": "meshes/m.obj", "size": [1, 1, 1]}),
      "pick_place.object.mesh", "not found")
    v("lift-height-true", _set(pp, ("pick_place", "lift_height"), True), "pick_place.lift_height")
    v("lift-height-string", _set(pp, ("pick_place", "lift_height"), "0.1"), "pick_place.lift_height")
    v("seed-negative", _set(gr, ("sim", "seed"), -1), "sim.seed", "greater than or equal to 0")
    v("seed-bool", _set(gr, ("sim", "seed"), True), "sim.seed")
    v("seed-float", _set(gr, ("sim", "seed"), 1.5), "sim.seed")
    v("ground-number", _set(gr, ("scene", "ground"), 1), "scene.ground")
    v("timestep-zero", _set(gr, ("sim", "timestep"), 0), "sim.timestep")
    v("timestep-nan", _set(gr, ("sim", "timestep"), float("nan")), "sim.timestep")
    v("gravity-inf", _set(gr, ("sim", "gravity"), [0, 0, float("-inf")]), "sim.gravity[2]")
    v("follow-obstacle-named-like-scene",
      _set(_set(ft, ("follow_target", "obstacles"), [{"name": "cube", "shape": "sphere", "size": [0.05]}]), ("scene", "objects"), [cube]),
      "follow_target.obstacles[0].name", "already used")
    v("follow-radius-bool", _set(ft, ("follow_target", "motion", "radius"), False), "follow_target.motion.radius")
    v("camera-width-float", _set(gs, ("grasp", "camera", "width"), 320.5), "grasp.camera.width")
    c.append(_validate("gripper-seed-1e-3-ok.yaml", _dump(gr).replace("rate: 2.0", "rate: 2e0"), 0, name="exponent-float-ok"))
    return c


def _panda_robot(urdf: str) -> dict:
    data = yaml.safe_load((ROBOTS / "panda.yaml").read_text())
    data["urdf"] = urdf
    return data


def robot_cases() -> list[Case]:
    base = _panda_robot("pybullet_data://franka_panda/panda.urdf")
    c = [_validate("panda.yaml", base, 0, name="robot-valid-panda")]

    def v(name, data, field_, expect=""):
        c.append(_validate(f"{name}.yaml", data, 2, field_, name=name, expect=expect))

    v("ik-backend-typo", _set(base, ("ik_backend", ), "placoo"), "ik_backend", "did you mean 'placo'")
    v("ik-backend-unknown", _set(base, ("ik_backend",), "ikfast"), "ik_backend", "known: lm, pink, placo")
    v("tcp-offset-bool", _set(base, ("arms", 0, "tcp_offset"), True), "arms[0].tcp_offset")
    v("home-bool", _set(base, ("arms", 0, "home", 2), False), "arms[0].home[2]")
    v("home-string", _set(base, ("arms", 0, "home", 2), "0.0"), "arms[0].home[2]")
    v("max-width-bool", _set(base, ("arms", 0, "gripper", "max_width"), True), "arms[0].gripper.max_width")
    v("schema-version-bool", _set(base, ("schema_version",), True), "schema_version")
    v("fixed-base-number", _set(base, ("fixed_base",), 0), "fixed_base")
    v("joint-index-bool", _set(_set(base, ("arms", 0, "joint_indices"), [True, 1, 2, 3, 4, 5, 6]), ("arms", 0, "joints"), None),
      "arms[0].joint_indices[0]")
    return c


def _urdf_text(mutate: tuple[str, str] | None = None) -> str:
    """Panda's URDF with absolute mesh paths (so a copy in any folder loads) and one text swap."""
    text = PANDA_URDF.read_text().replace('filename="package://meshes/', f'filename="{PANDA_URDF.parent}/meshes/')
    if mutate is not None:
        old, new = mutate
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def urdf_cases() -> list[Case]:
    robot = _dump(_panda_robot("panda.urdf"))
    joint4 = '<joint name="panda_joint4" type="revolute">'
    origin4 = '<origin rpy="1.57079632679 0 0" xyz="0.0825 0 0"/>'
    swaps = {
        "urdf-valid": None,
        "urdf-origin-nan": (origin4, '<origin rpy="1.57079632679 0 0" xyz="nan 0 0"/>'),
        "urdf-origin-inf": (origin4, '<origin rpy="inf 0 0" xyz="0.0825 0 0"/>'),
        "urdf-limit-nan": ('lower="-3.1416" upper="0.0"', 'lower="-3.1416" upper="NaN"'),
        "urdf-limit-neg-inf": ('lower="-3.1416" upper="0.0"', 'lower="-inf" upper="0.0"'),
        "urdf-not-a-number": (origin4, '<origin rpy="1.57079632679 0 0" xyz="zero 0 0"/>'),
        "urdf-broken-xml": (joint4, '<joint name="panda_joint4" type="revolute"'),
        "urdf-unknown-parent": ('<parent link="panda_link3"/>', '<parent link="panda_link33"/>'),
    }
    out = []
    for name, swap in swaps.items():
        ok = swap is None
        located = name != "urdf-unknown-parent"  # that one is reported at the arm joints it breaks
        out.append(Case(name, {"panda.urdf": _urdf_text(swap), "robot.yaml": robot}, ["validate", "{dir}/robot.yaml"],
                        0 if ok else 2, None if ok else "robot.yaml", "urdf" if located and not ok else None,
                        "panda.urdf:" if located and not ok and name != "urdf-not-a-number" else ""))
    return out


def cli_cases() -> list[Case]:
    gr, tr, gs = _task("gripper"), _task("trajectory"), _task("grasp")
    bad_hold = _dump(_set(gr, ("gripper", "hold_object"), "cub"))
    bad_wp = _dump(_set(tr, ("trajectory", "waypoints"), ["home", [0.0, 0.1]]))
    no_obj = _dump(_set(gs, ("grasp", "objects"), []))
    return [
        Case("cli-missing-file", {}, ["validate", "{dir}/nope.yaml"], 2, expect="nope.yaml: file not found"),
        Case("cli-empty-folder", {"empty/readme.txt": "no yaml here\n"}, ["validate", "{dir}/empty"], 2, expect="empty: no YAML files"),
        Case("cli-folder-ok", {"ok/gripper.yaml": (TASKS / "gripper.yaml").read_text()}, ["validate", "{dir}/ok"], 0),
        Case("cli-run-gripper-bad-hold", {"g.yaml": bad_hold}, ["run", "gripper", "{dir}/g.yaml"], 2, "g.yaml", "gripper.hold_object",
             "did you mean 'cube'"),
        Case("cli-run-trajectory-bad-wp", {"t.yaml": bad_wp}, ["run", "trajectory", "{dir}/t.yaml"], 2, "t.yaml", "trajectory.waypoints[1]"),
        Case("cli-run-grasp-no-objects", {"g.yaml": no_obj}, ["run", "grasp", "{dir}/g.yaml"], 2, "g.yaml", "grasp.objects"),
        Case("cli-run-seed-negative", {}, ["run", "gripper", "gripper", "--seed", "-1"], 2, expect="--seed"),
        Case("cli-run-unknown-task", {}, ["run", "gripper", "grippr"], 2, expect="did you mean"),
        Case("cli-run-unknown-robot", {}, ["run", "gripper", "gripper", "--robot", "pandaa"], 2, expect="did you mean 'panda'"),
        Case("cli-validate-unknown-option", {}, ["validate", "--strcit"], 2, expect="--strcit"),
    ]


def _both(name: str, files: dict[str, str], task: str, kind: str, file: str | None, field_: str | None, expect: str,
          extra: tuple[str, ...] = (), run_extra: tuple[str, ...] = ()) -> list[Case]:
    """The same input through ``validate`` and ``run KIND``: both must exit 2 with the same
    located line (``run`` before it simulates; the test makes building a world fail)."""
    return [Case(f"{name}-validate", files, ["validate", "{dir}/" + task, *extra], 2, file, field_, expect),
            Case(f"{name}-run", files, ["run", kind, "{dir}/" + task, *extra, *run_extra], 2, file, field_, expect)]


def parity_cases() -> list[Case]:
    """Inputs that ``validate`` once passed and ``run`` then rejected (exit 1 or 2), some only
    after simulating: each is now rejected by both, at the same FILE:LINE and field."""
    gr, tr, pp, gs = _task("gripper"), _task("trajectory"), _task("pick_place"), _task("grasp")
    out: list[Case] = []
    # A suction gripper is tested by holding an object: without one the run failed in its "place" phase.
    suction = _set(gr, ("robots", 0, "robot"), "kuka_iiwa_suction")
    del suction["gripper"]["hold_object"]
    out += _both("suction-no-hold-object", {"g.yaml": _dump(suction)}, "g.yaml", "gripper", "g.yaml", "gripper.hold_object",
                 "a suction gripper is tested by holding an object")
    # A hold object wider than the open gripper: the run failed after simulating ("still between both fingers").
    wide = _set(gr, ("scene", "objects", 0, "size"), [0.09, 0.1, 0.04])
    out += _both("hold-object-too-wide", {"g.yaml": _dump(wide)}, "g.yaml", "gripper", "g.yaml", "scene.objects[0].size",
                 "90.0 mm across its narrowest side, not less than the gripper's max_width 80.0 mm")
    # An arm joint without a velocity limit: timed moves divide by it (found when the first move was planned).
    no_vel = _urdf_text(('lower="-3.1416" upper="0.0" velocity="2.1750"', 'lower="-3.1416" upper="0.0" velocity="0"'))
    robot = _dump(_panda_robot("panda.urdf"))
    for kind, data in (("trajectory", tr), ("pick-place", pp), ("grasp", gs)):
        task = _set(data, ("robots", 0), {"robot_config_file": "robot.yaml"})
        out += _both(f"velocity-limit-missing-{kind}", {"panda.urdf": no_vel, "robot.yaml": robot, "t.yaml": _dump(task)},
                     "t.yaml", kind, "robot.yaml", "drives.velocity_limits", "joint 'panda_joint4' has no velocity limit")
    # The same joint given a velocity limit in the robot YAML is fine (validate only: no simulation here).
    fixed = _panda_robot("panda.urdf")
    fixed["drives"] = {**fixed.get("drives", {}), "velocity_limits": {"panda_joint4": 2.175}}
    out.append(Case("velocity-limit-from-drives-ok", {"panda.urdf": no_vel, "robot.yaml": _dump(fixed),
                                                       "t.yaml": _dump(_set(tr, ("robots", 0), {"robot_config_file": "robot.yaml"}))},
                    ["validate", "{dir}/t.yaml"], 0))
    # A variant's value is checked with its robot, and again when that robot runs the task.
    variant = dict(pp, variants={"ur5e_robotiq_2f85": {"pick_place.lift_height": True}})
    out += _both("variant-bool-value", {"p.yaml": _dump(variant)}, "p.yaml", "pick-place", "p.yaml",
                 "variants.ur5e_robotiq_2f85.pick_place.lift_height", "", run_extra=("--robot", "ur5e_robotiq_2f85"))
    # Fixtures whose parts overlap; an object inside a fixture part.
    bins = _task("pick_place_bins")
    clash = copy.deepcopy(bins)
    clash["scene"]["fixtures"][1]["position"] = list(clash["scene"]["fixtures"][0]["position"])
    out += _both("fixture-overlap", {"b.yaml": _dump(clash)}, "b.yaml", "pick-place", "b.yaml", "scene.fixtures[1].position",
                 "overlaps fixture part 'bin_a/floor'")
    # --set names a field: its value is checked as if written in the file.
    out += _both("set-hold-object-typo", {"g.yaml": _dump(gr)}, "g.yaml", "gripper", None, None,
                 "--set gripper.hold_object: no object 'cub' in scene.objects; did you mean 'cube'",
                 extra=("--set", "gripper.hold_object=cub"))
    return out


def _deep(kind: str) -> str:
    head = "schema_version: 1\ntask: gripper\nrobots:\n  - robot: panda\nscene:\n  objects: "
    if kind == "flow":
        return head + "[" * 25_000 + "]" * 25_000 + "\n"
    if kind == "block":
        return head + "\n" + "  - " * 1 + "- " * 25_000 + "x\n"
    return head + "{a: " * 25_000 + "1" + "}" * 25_000 + "\n"


def _big() -> str:
    row = "[" + ", ".join(str(i) for i in range(60)) + "]"
    return "schema_version: 1\ntask: gripper\n" + "".join(f"k{i}: {row}\n" for i in range(30_000))


def subprocess_cases() -> list[Case]:
    """Inputs that crashed or stalled the YAML library: run as separate processes (a crash must
    not take the test session down), through both ``validate`` and ``run``."""
    out = []
    for kind in ("flow", "block", "map"):
        out.append(Case(f"deep-{kind}-validate", {"deep.yaml": _deep(kind)}, ["validate", "{dir}/deep.yaml"], 2, "deep.yaml", None,
                        "nested more than 100 levels", subprocess=True))
    out.append(Case("deep-flow-run", {"deep.yaml": _deep("flow")}, ["run", "gripper", "{dir}/deep.yaml"], 2, "deep.yaml", None,
                    "nested more than 100 levels", subprocess=True))
    out.append(Case("big-validate", {"big.yaml": _big()}, ["validate", "{dir}/big.yaml"], 2, "big.yaml", None, "KiB", subprocess=True))
    out.append(Case("big-run", {"big.yaml": _big()}, ["run", "trajectory", "{dir}/big.yaml"], 2, "big.yaml", None, "KiB", subprocess=True))
    return out


def all_cases() -> list[Case]:
    rng = random.Random(SEED)
    return [*task_cases(rng), *specific_task_cases(), *robot_cases(), *urdf_cases(), *cli_cases(), *parity_cases(),
            *subprocess_cases()]


def write(case: Case, folder: Path) -> list[str]:
    """Write the case's files under ``folder``; the command line with ``{dir}`` filled in."""
    for rel, text in case.files.items():
        p = folder / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return [a.replace("{dir}", str(folder)) for a in case.args]


if __name__ == "__main__":  # write the corpus out, one folder per case
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "corpus")
    for case in all_cases():
        print(case.name, *write(case, out / case.name), sep="\t")
