"""The episode engine and the task registry: one table of kinds, one CLI factory, episodes that
give the same record wherever they run, stops honoured by every kind, and a new kind in one file."""

from __future__ import annotations

import dataclasses
import importlib
import json
import pickle
import sys
import textwrap

import pytest
import yaml
from _cli import run_main
from test_golden_reports import GOLDEN, _assert_same

import robocfg
from robocfg.config.task import TASK_MODELS, params_model
from robocfg.engine import (
    EpisodeSpec,
    RunOptions,
    open_session,
    registered,
    run_episode,
    runner_for,
)
from robocfg.engine.registry import builtin_command, command_name, unregister_task
from robocfg.engine.runner import TaskCommand
from robocfg.engine.spec import close_cached_session

COMMON_FLAGS = ("--robot", "--arm", "--seed", "--episodes", "--json", "--record", "--record-episode", "--gui",
                "--quiet", "--min-success")


def test_registry_and_config_table_agree():
    kinds = registered()
    assert set(kinds) == set(TASK_MODELS) == {"gripper", "trajectory", "follow_target", "pick_place", "grasp",
                                              "pick_place_many"}
    for kind, runner in kinds.items():
        assert runner.kind == kind and runner.params is params_model(kind)
        assert dataclasses.is_dataclass(runner.report)
    with pytest.raises(robocfg.NotFound, match="did you mean 'pick_place'"):
        runner_for("pick_plac")


def test_every_builtin_kind_runner_is_its_command_face():
    """``run KIND --help`` is built from the kind's light ``robocfg.runners.<kind>_command`` class;
    the runner subclasses it and redefines none of its attributes, so the help, the options and
    the episode flag the command line offers are the runner's."""
    for kind, runner in registered().items():
        command = builtin_command(kind)
        assert command is not None and command.kind == kind and issubclass(runner, command), kind
        faces = list(TaskCommand.__annotations__)
        assert sorted(faces) == ["Options", "description", "episodic", "kind", "summary", "verb"]
        assert [n for n in faces if n in vars(runner)] == [], kind  # all inherited from the face
        assert command.episodic == runner.episodic and command.Options is runner.Options, kind
    assert builtin_command("drop") is None


@pytest.mark.parametrize("kind", sorted(TASK_MODELS))
def test_every_kind_gets_the_same_options_and_a_report_schema(kind, capsys, monkeypatch):
    code, out, err = run_main(["run", command_name(kind), "--help"], capsys, monkeypatch)
    assert code == 0, err
    assert all(flag in out for flag in COMMON_FLAGS), out
    code, out, err = run_main(["schema", f"report-{command_name(kind)}"], capsys, monkeypatch)
    assert code == 0 and "schema_version" in json.loads(out)["properties"]


def test_episodes_run_in_any_order_and_alone_give_the_batch_records():
    """Episodes 1 then 0 of a session, and episode 1 from a pickled spec in a fresh session, equal
    episodes 1 and 0 of the batch run stored as the golden report (seed 7)."""
    golden = json.loads((GOLDEN / "pick-place.json").read_text())["episodes"]
    task = robocfg.load_task("pick_place")
    options = RunOptions(seed=7)
    with open_session(task, options) as session:
        late, early = session.run(1), session.run(0)
    _assert_same(json.loads(json.dumps(dataclasses.asdict(late))), golden[1])
    _assert_same(json.loads(json.dumps(dataclasses.asdict(early))), golden[0])
    spec = pickle.loads(pickle.dumps(EpisodeSpec.of(task, 1, dataclasses.replace(options, log=print))))
    assert spec.seed == 7 and spec.options.log is None  # in-process hooks do not travel
    try:
        alone = run_episode(spec)
    finally:
        close_cached_session()
    _assert_same(json.loads(json.dumps(dataclasses.asdict(alone))), golden[1])


@pytest.mark.parametrize("kind", ["gripper", "trajectory", "follow_target"])
def test_one_episode_kinds_stop_when_asked(kind):
    task = robocfg.load_task(kind)
    calls = []

    def stop() -> bool:
        calls.append(1)
        return True

    report = runner_for(kind)(task, RunOptions(should_stop=stop)).run().report
    assert report.interrupted and calls and report.episodes_finished() == 0
    assert report.sim_time < 0.1  # stopped at the first check, not after the whole run


def test_one_episode_kinds_refuse_several_episodes(capsys, monkeypatch):
    code, _, err = run_main(["run", "gripper", "-n", "3"], capsys, monkeypatch)
    assert code == 2 and "runs one episode" in err and "Traceback" not in err


TOY_KIND = textwrap.dedent('''
    """A toy task kind in one file: drop a box from a seeded height and check it comes to rest."""
    from dataclasses import dataclass, field

    from pydantic import Field

    from robocfg.config.scene import Body
    from robocfg.config.types import Frozen
    from robocfg.engine import EpisodeSession, EpisodicRunner, register_task
    from robocfg.engine.runner import EpisodesReport


    class DropParams(Frozen):
        height: float = Field(0.3, description="Drop height of the box centre (m).")
        height_range: float = Field(0.1, description="± random change of the height (m).")
        size: float = Field(0.04, description="Box edge (m).")


    @dataclass
    class DropEpisode:
        index: int
        start_z: float
        final_z: float
        success: bool
        failed_phase: str | None
        reason: str


    @dataclass
    class DropReport(EpisodesReport):
        seed: int
        episodes: list[DropEpisode] = field(default_factory=list)
        interrupted: bool = False


    class DropSession(EpisodeSession[DropEpisode]):
        def episode(self, k, recorder):
            p = self.task.config.drop
            z = p.height + self.rng(k).uniform(-1, 1) * p.height_range
            box = self.spawn(Body(name="box", shape="box", size=[p.size] * 3, mass=0.1, position=[0.5, 0.4, z]))
            self.world.step(round(1.0 / self.world.dt))
            final = float(self.world.body_pose(box)[0][2])
            ok = abs(final - p.size / 2) < 0.002
            return DropEpisode(k, round(z, 6), round(final, 6), ok, None if ok else "rest", "at rest" if ok else "moving")

        def report(self, records, interrupted):
            return DropReport(self.seed, records, interrupted)


    @register_task
    class DropRunner(EpisodicRunner):
        kind = "drop"
        params = DropParams
        report = DropReport
        summary = "Drop a box and check it comes to rest on the ground."
        verb = "at rest"

        def open_session(self):
            return DropSession(self.task, self.options)
''')


@pytest.fixture
def toy_kind(tmp_path, monkeypatch):
    (tmp_path / "toy_drop_kind.py").write_text(TOY_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.import_module("toy_drop_kind")
    yield
    unregister_task("drop")
    sys.modules.pop("toy_drop_kind", None)
    assert "drop" not in registered() and "drop" not in TASK_MODELS


def test_a_task_kind_added_as_the_architecture_recipe_says(toy_kind, tmp_path, capsys, monkeypatch):
    task = tmp_path / "drop.yaml"
    task.write_text(yaml.safe_dump({"schema_version": 1, "task": "drop", "robots": [{"robot": "panda"}],
                                    "drop": {"height": 0.25}}))
    code, out, err = run_main(["validate", str(task)], capsys, monkeypatch)
    assert code == 0, out + err
    code, out, err = run_main(["run", "drop", str(task), "-n", "3", "--seed", "5", "--json", str(tmp_path / "r.json"), "-q"],
                              capsys, monkeypatch)
    assert code == 0, out + err
    assert out.startswith("ok: 3/3 episodes succeeded")
    doc = json.loads((tmp_path / "r.json").read_text())
    starts = [e["start_z"] for e in doc["episodes"]]
    assert doc["seed"] == 5 and len(set(starts)) == 3 and all(0.15 <= z <= 0.35 for z in starts)
    assert all(abs(e["final_z"] - 0.02) < 0.002 for e in doc["episodes"])  # really fell and came to rest
    code, out, _ = run_main(["schema", "report-drop"], capsys, monkeypatch)
    assert code == 0 and "final_z" in out
    bad = tmp_path / "bad.yaml"
    bad.write_text("schema_version: 1\ntask: drop\nrobots: [{robot: panda}]\ndrop: {hieght: 1}\n")
    code, _, err = run_main(["validate", str(bad)], capsys, monkeypatch)
    assert code == 2 and "drop.hieght" in err and "did you mean 'height'" in err


def test_an_episode_has_the_same_physics_first_in_a_session_or_after_another():
    """Episode 0 of pick_place on the xArm6 (seed 5) run first in a session, and again after it
    ran: the object ends in the same state, bit for bit (a body made before the snapshot and put
    in place each episode gave the first run other physics from its lowering on)."""
    task = robocfg.load_task("pick_place", robot="xarm6")
    ends = []
    with open_session(task, RunOptions(seed=5)) as session:
        for _ in range(2):
            record = session.run(0)
            w = session.world
            body = w.body_id("cube")
            ends.append((record, w.body_pose_tuple(body), tuple(map(tuple, w.body_velocity(body)))))
    assert ends[0][0].success
    assert ends[0] == ends[1]
