"""``robocfg bench ik``: IK success rate and time per query, our backends vs PyBullet's IK."""

from __future__ import annotations

from typing import Annotated

import typer

from robocfg.cli.common import JsonOpt, console, write_json

bench_app = typer.Typer(help="Benchmarks measured side by side with a reference.", no_args_is_help=True)


@bench_app.command("ik")
def bench_ik(
    robot: Annotated[str, typer.Option("--robot", "-r", help="Robot name or robot YAML path.")] = "panda",
    n: Annotated[int, typer.Option("--targets", "-n", help="Number of random targets.", min=1)] = 1000,
    backends: Annotated[str, typer.Option("--backends", help="'all' or comma-separated backend names.")] = "all",
    budget_ms: Annotated[float, typer.Option("--budget-ms", help="Time budget per query (ms).", min=0.1)] = 5.0,
    frame: Annotated[str, typer.Option("--frame", help="Target frame: ee (TRAC-IK's protocol) or tcp.")] = "ee",
    seed: Annotated[int, typer.Option("--seed", help="Seed for the target configurations.")] = 0,
    budget_clock: Annotated[str, typer.Option("--budget-clock", help="wall (the protocol) or cpu (budget on this thread's CPU time; for shared machines).")] = "wall",
    n_slow: Annotated[int | None, typer.Option("--n-slow", help="Run pink and placo on the first N targets only.", min=1)] = None,
    no_pybullet: Annotated[bool, typer.Option("--no-pybullet", help="Skip the PyBullet reference row.")] = False,
    json_path: JsonOpt = None,
) -> None:
    """IK success rate and time per query, each backend beside PyBullet's IK. TRAC-IK's protocol:
    N configurations uniform within limits, targets = FK, seed = mid-limits, success = 1e-5 m and
    1e-5 rad and within limits, times include failures."""
    from rich.table import Table

    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.errors import ConfigError, Problem
    from robocfg.kinematics.ik.bench import bench_ik as run
    from robocfg.kinematics.ik.registry import get_backend, known_backends
    from robocfg.sim.ik_reference import reference_row

    if budget_clock not in ("wall", "cpu"):
        raise ConfigError([Problem("<command line>", None, None, "--budget-clock", f"expected wall or cpu, got {budget_clock!r}")])
    names = known_backends() if backends == "all" else [b.strip() for b in backends.split(",") if b.strip()]
    for name in names:
        get_backend(name)  # NotFound lists the known names
    checked = load_robot(catalog.find("robots", robot))
    err = console(stderr=True)
    result = run(checked, n=n, backends=names, seed=seed, time_budget=budget_ms / 1000.0, frame=frame,
                 reference=None if no_pybullet else reference_row, budget_clock=budget_clock,
                 n_by_backend={"pink": n_slow, "placo": n_slow} if n_slow else None, progress=lambda msg: err.print(f"[dim]{msg}[/dim]"))
    table = Table(title=f"IK on {result.robot} ({frame} frame), n = {n}, budget {budget_ms:g} ms ({budget_clock}), seed {seed}")
    for col in ("backend", "success %", "≤1 mm/0.01 rad %", "outside limits %", "mean ms", "median ms", "p95 ms",
                "CPU mean ms", "note"):
        table.add_column(col)
    for r in result.rows:
        table.add_row(r.backend, f"{r.success_pct:.1f}", f"{r.success_loose_pct:.1f}", f"{r.outside_limits_pct:.1f}",
                      f"{r.mean_ms:.3f}", f"{r.median_ms:.3f}", f"{r.p95_ms:.3f}", f"{r.cpu_mean_ms:.3f}", r.note)
    out = console()
    out.print(table)
    out.print(f"machine: {result.machine}; 1-min load average {result.load_average[0]:.2f} before, "
              f"{result.load_average[1]:.2f} after (times are wall-clock; CPU = this process only)")
    write_json(json_path, result)
