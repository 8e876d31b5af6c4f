"""``start()`` of the executors: the workers (pool processes, Ray actors) are started and their
worlds built before ``run``, which then runs every batch on those same workers and gives the
records and report of a run that started its own (what bench_scaling times apart)."""

from __future__ import annotations

import psutil
import ray

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions
from robocfg.executors.pool import ProcessPool
from robocfg.executors.ray_pool import RayPool
from robocfg.executors.recipe import EngineRecipe
from robocfg.executors.session import plan_batches


def _recipe(episodes: int) -> EngineRecipe:
    return EngineRecipe.of(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=4, episodes=episodes))


def test_a_started_pool_runs_on_the_workers_it_started():
    recipe, batches = _recipe(3), plan_batches(3, 2, False)
    alone = ProcessPool(2).run(recipe, batches)
    pool = ProcessPool(2)
    pool.start(recipe)
    started = list(pool.pids)
    assert len(started) == 2 and all(psutil.pid_exists(p) for p in started)
    seen: list[list[int]] = []
    out = pool.run(recipe, batches, on_episode=lambda run: seen.append(list(pool.pids)))
    assert seen and all(p == started for p in seen)  # no new worker was spawned for the run
    assert not any(psutil.pid_exists(p) and psutil.Process(p).status() != psutil.STATUS_ZOMBIE for p in started)
    assert out.records == alone.records and out.report == alone.report and not out.lost


def test_a_started_ray_pool_runs_on_the_actors_it_started():
    recipe, batches = _recipe(2), plan_batches(2, 1, False)
    ray.init(num_cpus=1, include_dashboard=False)
    try:
        alone = RayPool(1).run(recipe, batches)
        pool = RayPool(1)
        pool.start(recipe)
        started = ray.get([a.pid.remote() for a in pool.actors])
        seen: list[list[int]] = []
        out = pool.run(recipe, batches, on_episode=lambda run: seen.append(ray.get([a.pid.remote() for a in pool.actors])))
        assert seen and all(p == started for p in seen)  # the same actor processes ran every batch
        assert pool.actors == []  # ended with the run
    finally:
        ray.shutdown()
    assert out.records == alone.records and out.report == alone.report and not out.lost


def test_a_local_ray_started_for_the_run_gives_its_actors_the_drivers_niceness():
    """Ray's own default starts workers at niceness 15, where an actor yields its core to every
    ordinary process (a pool worker, another job): the local Ray that ``--executor ray`` starts
    runs them at the driver's niceness, as a process pool's workers run."""
    import os

    recipe = _recipe(1)
    assert not ray.is_initialized()
    pool = RayPool(1)
    pool.start(recipe)  # starts a local Ray, as the CLI does without --ray-address
    try:
        assert [s.niceness for s in pool.starts] == [os.nice(0)]
        out = pool.run(recipe, plan_batches(1, 1, False))
    finally:
        if ray.is_initialized():
            ray.shutdown()
    assert not out.lost and len(out.records) == 1


def test_kept_ray_actors_open_the_next_recipe_in_the_same_process_with_the_same_results():
    """``RayPool(keep=True)``: after a run the actors stay (sessions closed); the next kept run
    reopens its own recipe in those processes and gives what new actors give."""
    from robocfg.executors import ray_pool

    other = EngineRecipe.of(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=9, episodes=2))
    ray.init(num_cpus=2, include_dashboard=False)
    try:
        fresh = RayPool(1).run(other, plan_batches(2, 1, False))
        RayPool(1, keep=True).run(_recipe(1), plan_batches(1, 1, False))
        assert len(ray_pool._KEPT.actors) == 1
        pid = ray.get(ray_pool._KEPT.actors[0].pid.remote())
        kept = RayPool(1, keep=True)
        kept.start(other)
        assert [s.pid for s in kept.starts] == [pid] and not ray_pool._KEPT.actors  # the kept process, taken
        out = kept.run(other, plan_batches(2, 1, False))
        assert len(ray_pool._KEPT.actors) == 1
        ray_pool.release_kept(ray)
        assert not ray_pool._KEPT.actors
    finally:
        ray.shutdown()
    assert out.records == fresh.records and out.report == fresh.report and not out.lost
