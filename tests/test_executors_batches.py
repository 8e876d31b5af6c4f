"""What a batch costs around its episodes: a run without a dataset never loads the dataset modules
(a Ray actor paid their imports inside its first batch), each committed batch carries the wall-clock
stamps of its start and end in the worker (bench_scaling places batches on one time line with
them), and a pool's workers all stop at the end of a run."""

from __future__ import annotations

import itertools
import subprocess
import sys
import time

import numpy as np
import psutil
from _cli import ROOT

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions
from robocfg.executors.pool import ProcessPool
from robocfg.executors.recipe import EngineRecipe
from robocfg.executors.session import DatasetTarget, plan_batches


def _recipe(episodes: int, dataset: DatasetTarget | None = None) -> EngineRecipe:
    return EngineRecipe.of(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=4, episodes=episodes), dataset)


def test_a_batch_without_a_dataset_loads_no_dataset_module():
    code = ("import sys\n"
            "from robocfg.checks import load_task; from robocfg.config import catalog\n"
            "from robocfg.engine import RunOptions\n"
            "from robocfg.executors.recipe import EngineRecipe\n"
            "from robocfg.executors.session import Batch, run_batch\n"
            "r = EngineRecipe.of(load_task(catalog.find('tasks', 'pick_place')), RunOptions(seed=0, episodes=1))\n"
            "s = r.open(); done = run_batch(s, None, Batch(0, (0,))); s.close()\n"
            "assert done.shard is None and len(done.runs) == 1\n"
            "print(sorted(m for m in sys.modules if m.startswith(('robocfg.datasets.shards', 'robocfg.datasets.sink',"
            " 'scipy.spatial', 'pyarrow'))))\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_only_a_recording_recipe_preloads_the_shard_writer(tmp_path):
    target = DatasetTarget(tmp_path / "ds", "lerobot", 20, "success", "pick", {})
    assert "robocfg.datasets.shards" not in _recipe(1).preload
    assert "robocfg.datasets.shards" in _recipe(1, target).preload
    assert _recipe(1).preload[-1] == "robocfg.runners.pick_place"


def test_batches_carry_their_wall_clock_span_and_the_workers_all_stop():
    recipe = _recipe(4)
    pool = ProcessPool(2)
    pool.start(recipe)
    pids = list(pool.pids)
    called = time.time()
    out = pool.run(recipe, plan_batches(4, 2, False))
    returned = time.time()
    assert not out.lost and len(out.done) == 4
    by_worker: dict[int, list] = {}
    for b in out.done:
        assert called <= b.wall[0] <= b.wall[1] <= returned
        assert b.wall[1] - b.wall[0] >= sum(r.wall for r in b.runs) * 0.99  # the episodes ran inside it
        by_worker.setdefault(b.pid, []).append(b)
    assert set(by_worker) <= set(pids)
    for bs in by_worker.values():  # one worker runs one batch at a time
        bs.sort(key=lambda b: b.wall[0])
        assert all(a.wall[1] <= b.wall[0] for a, b in itertools.pairwise(bs))
    assert not any(psutil.pid_exists(p) and psutil.Process(p).status() != psutil.STATUS_ZOMBIE for p in pids)


def _finish_spread(sizes_of: list[tuple[int, ...]], workers: int, duration: list[float]) -> float:
    """Hand ``sizes_of`` (batches' episode indices) to whichever of ``workers`` is free first, as
    the executors do; episode k takes ``duration[k]``: the spread of the workers' finishing times."""
    free = [0.0] * workers
    for indices in sizes_of:
        i = free.index(min(free))
        free[i] += sum(duration[k] for k in indices)
    return max(free) - min(free)


def test_recording_batches_shrink_so_the_workers_finish_within_one_episode():
    rng = np.random.default_rng(0)
    for episodes, workers in [(256, 16), (64, 2), (1000, 8), (37, 3), (128, 16)]:
        batches = plan_batches(episodes, workers, True)
        assert [k for b in batches for k in b.indices] == list(range(episodes))
        assert [b.id for b in batches] == list(range(len(batches)))
        sizes = [len(b.indices) for b in batches]
        assert max(sizes) <= 8 and sizes == sorted(sizes, reverse=True) and sizes[-1] == 1
        assert len(batches) <= episodes // 2 + 2 * workers  # still fewer shards than episodes
        for _ in range(20):  # episodes of unequal length (0.5-1.5 units): the tail stays one episode
            duration = list(rng.uniform(0.5, 1.5, episodes))
            assert _finish_spread([b.indices for b in batches], workers, duration) <= 1.5
    assert all(len(b.indices) == 1 for b in plan_batches(256, 16, False))
