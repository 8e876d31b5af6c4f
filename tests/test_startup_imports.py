"""What a fresh robocfg process imports: the libraries a command does not need stay unloaded
(`robocfg --help`, `robocfg run pick-place --help`, `robocfg validate`, a pick-place process up to
its world), read from ``sys.modules`` when the real command exits. A behaviour check of the
start-up work (benchmarks/bench_startup.py measures its time; no wall-clock assert here)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

# never needed before an episode of a state-only pick-place run, nor by help or validate
NEVER = ["ray", "pyarrow", "av", "h5py", "ompl", "toppra", "matplotlib", "imageio", "trimesh", "networkx",
         "gymnasium", "viser", "placo", "pink", "yourdfpy", "PIL"]

# the built-in runners other than pick-place's
OTHER_KINDS = ["robocfg.runners.grasp", "robocfg.runners.trajectory", "robocfg.runners.follow_target",
               "robocfg.runners.gripper", "robocfg.runners.pick_place_many"]


def _imported(tmp_path: Path, cli: list[str] | None = None, code: str | None = None) -> set[str]:
    """Every module in ``sys.modules`` when a fresh ``robocfg CLI...`` process (or ``python -c
    CODE``) exits, run in the repository root."""
    out_file = tmp_path / "modules.txt"
    probe = (f"import atexit, sys; atexit.register(lambda: open({str(out_file)!r}, 'w').write(chr(10).join(sys.modules)))\n")
    if cli is not None:
        probe += f"import runpy; sys.argv = ['robocfg', *{cli!r}]; runpy.run_module('robocfg', run_name='__main__')\n"
    else:
        probe += f"{code}\n"
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    return set(out_file.read_text().split())


def _heavy(names: set[str], heavy: list[str]) -> list[str]:
    return sorted(h for h in heavy if any(n == h or n.startswith(h + ".") for n in names))


def test_root_help_imports_no_numpy_pydantic_or_simulator(tmp_path) -> None:
    names = _imported(tmp_path, ["--help"])
    assert "robocfg.cli.validate" in names  # the probe sees the command's modules
    assert _heavy(names, [*NEVER, "numpy", "pydantic", "scipy", "pybullet", "pinocchio", "rich"]) == []


@pytest.mark.parametrize("kind", ["pick_place", "trajectory", "grasp"])
def test_run_kind_help_imports_no_episode_code(tmp_path, kind: str) -> None:
    """``run KIND --help`` reads the kind's command face (help, own options), not its runner: no
    numpy, config models, session, simulator, kinematics or scipy; and no pydantic (typer's
    adapters for the flags passed by: robocfg.cli.flags)."""
    names = _imported(tmp_path, ["run", kind.replace("_", "-"), "--help"])
    assert f"robocfg.runners.{kind}_command" in names  # the kind's options come from its command face
    assert _heavy(names, [*NEVER, "numpy", "pydantic", "scipy", "pybullet", "pinocchio"]) == []
    runners = {f"robocfg.runners.{kind}", *OTHER_KINDS, "robocfg.runners.pick_place"}
    assert sorted(runners & names) == []
    assert {"robocfg.engine.session", "robocfg.engine.spec", "robocfg.config.task", "robocfg.checks"} & names == set()


def test_run_help_lists_every_kind(tmp_path) -> None:
    names = _imported(tmp_path, ["run", "--help"])
    assert {"robocfg.runners.pick_place", *OTHER_KINDS} <= names


def test_validating_a_pick_place_of_a_box_imports_no_trimesh(tmp_path) -> None:
    names = _imported(tmp_path, ["validate", "robocfg/data/tasks/pick_place.yaml"])
    assert "robocfg.checks.grip_force" in names  # the checks that measure the object ran
    assert _heavy(names, [*NEVER, "pybullet"]) == []
    # the reach check ran (validate asks the kind's command face), the episode code was not loaded
    assert {"robocfg.motion.reach", "robocfg.runners.pick_place_command"} <= names
    assert sorted({"robocfg.runners.pick_place", "robocfg.runners.pick_place_machine", *OTHER_KINDS} & names) == []
    assert "importlib.metadata" not in names  # pydantic's plugin loader without it (robocfg.config.pydantic_plugins)


def test_a_pick_place_process_to_its_first_episode_imports_only_what_it_runs(tmp_path) -> None:
    """The fixed start of every process (a pool worker, a Ray actor, ``robocfg run``): no
    scipy.interpolate (splines are robocfg.motion.cubic), no scipy.spatial (rotations in closed
    form), no trimesh (a box's shape without it)."""
    code = ("from robocfg.checks.task import load_task; from robocfg.config import catalog; "
            "from robocfg.engine import RunOptions, open_session; "
            "s = open_session(load_task(catalog.find('tasks', 'pick_place')), RunOptions(seed=0)); "
            "assert s.run(0).success; s.close()")
    names = _imported(tmp_path, code=code)
    assert {"pybullet", "pinocchio", "robocfg.motion.cubic"} <= names  # the probe sees the episode's modules
    assert _heavy(names, [*NEVER, "scipy.interpolate", "scipy.spatial", "scipy.optimize", "scipy.sparse"]) == []
    assert "scipy.linalg" not in names and "scipy.linalg._flapack" in names  # LAPACK without scipy.linalg
    assert "scipy" not in names  # nor scipy's __init__ (its version checks)
    assert [m for m in OTHER_KINDS if m in names] == []  # the registry loaded this kind's runner only
    other_models = [f"robocfg.config.{m}" for m in ("gripper_task", "trajectory_task", "follow_target_task",
                                                      "grasp_task", "multi_pick")]
    assert [m for m in other_models if m in names] == []  # nor the other kinds' config models
    ik = {"robocfg.kinematics.ik.lm", "robocfg.kinematics.ik.pink_qp", "robocfg.kinematics.ik.placo_qp"}
    assert ik & names == {"robocfg.kinematics.ik.lm"}  # the IK backend it solves with, not the QP ones
    assert "importlib.metadata" not in names  # pydantic's plugin loader without it (robocfg.config.pydantic_plugins)


def test_lapack_routines_are_scipys_own_functions(tmp_path) -> None:
    """Loaded before ``scipy`` (its ``__init__`` not run), the routines are the objects scipy.linalg.lapack then
    gives (the same results); and they solve."""
    code = ("import numpy as np; from robocfg.geometry.lapack import lapack; import sys\n"
            "dposv, dgtsv = lapack('dposv'), lapack('dgtsv')\n"
            "assert 'scipy.linalg' not in sys.modules and 'scipy' not in sys.modules  # nor scipy's __init__\n"
            "H, g = np.array([[4.0, 1.0], [1.0, 3.0]]), np.array([1.0, 2.0])\n"
            "assert np.allclose(H @ dposv(H, g)[1], g)\n"
            "import scipy.linalg.lapack as l; assert l.dposv is dposv and l.dgtsv is dgtsv")
    _imported(tmp_path, code=code)


def test_a_mesh_object_still_loads_trimesh_on_demand() -> None:
    from robocfg.assets.object_shape import object_shape
    from robocfg.config.scene import Body

    shape = object_shape(Body(name="ball", shape="sphere", size=[0.03]), ROOT)
    assert shape.extents() == pytest.approx([0.06, 0.06, 0.06], abs=1e-9)


@pytest.mark.parametrize("extents", [[0.05, 0.05, 0.05], [0.04, 0.06, 0.08], [0.3, 0.02, 0.11]])
def test_box_part_is_trimesh_box_bit_for_bit(extents) -> None:
    """The box built without trimesh has trimesh's vertices, faces, normals and face areas, so
    the surface samples and grasp choices of a box object are the ones trimesh gave."""
    import trimesh

    from robocfg.assets.mesh_part import MeshPart

    theirs, ours = trimesh.creation.box(extents=extents), MeshPart.box(extents)
    for name in ("vertices", "faces", "face_normals", "triangles", "area_faces"):
        a, b = np.asarray(getattr(theirs, name)), getattr(ours, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
    assert ours.area == theirs.area


def test_converted_part_keeps_trimesh_areas() -> None:
    import trimesh

    from robocfg.assets.mesh_part import MeshPart

    theirs = trimesh.creation.capsule(height=0.05, radius=0.02, count=[16, 16])
    ours = MeshPart.of(theirs)
    assert np.array_equal(ours.area_faces, theirs.area_faces) and ours.area == theirs.area
    assert np.array_equal(ours.face_normals, theirs.face_normals)
