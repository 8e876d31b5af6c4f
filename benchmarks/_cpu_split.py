"""CPU time of a run split by part (``time.process_time``), for ``bench_obstacle_modes``.

:class:`Split` wraps named functions for the duration of a ``with`` block. Time is *exclusive*:
a wrapped call running inside another is charged to the inner one only, so the parts and
"other" add up to the CPU time of the block. ``stepSimulation`` is charged per phase (the phase
comes from a callable, e.g. the state machine's mover), with its step count, so the split gives
physics steps and µs per step by phase. A part marked ``nested_label`` takes its caller's part in
its name (IK inside the grasp choice vs inside a planned goal).

A part whose function does not exist (older code measured with ``PYTHONPATH`` pointing at
an earlier checkout) is left out. Each wrapped call costs two ``process_time`` reads (≈ 0.5–2 µs; ≈ 1–2 % of a physics step):
the benchmark's figures from runs without the split stay the ones to compare.
"""

from __future__ import annotations

import importlib
import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

PHYSICS = "physics"


class Split:
    """CPU seconds per part; ``phase_of()`` names the current phase (physics is split by it)."""

    def __init__(self, parts: list[tuple[str, str | None, str, str]], nested: tuple[str, ...] = ()):
        self.parts, self.nested = parts, set(nested)
        self.cpu: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.steps: dict[str, int] = defaultdict(int)  # physics steps per phase
        self.phase_of: Callable[[], str] = lambda: "setup"
        self._stack: list[str] = []
        self._last = 0.0
        self._undo: list[tuple[Any, str, Any]] = []

    def _charge(self) -> float:
        now = time.process_time()
        self.cpu[self._stack[-1] if self._stack else "other"] += now - self._last
        self._last = now
        return now

    def _wrap(self, f: Any, label: str) -> Any:
        split = self

        def timed(*a: Any, **k: Any) -> Any:
            name = label
            if label in split.nested and split._stack:
                name = f"{label} in {split._stack[-1]}"
            elif label == PHYSICS:
                phase = split.phase_of()
                name = f"{PHYSICS}: {phase}"
                split.steps[phase] += 1
            split._charge()
            split._stack.append(name)
            split.calls[name] += 1
            try:
                return f(*a, **k)
            finally:
                split._charge()
                split._stack.pop()

        return timed

    def __enter__(self) -> Split:
        for module, cls, fn, label in self.parts:
            holder = importlib.import_module(module)
            if cls is not None:
                holder = getattr(holder, cls)
            original = holder.__dict__.get(fn) if cls is not None else getattr(holder, fn, None)
            if original is None:  # a part older code does not have (a run against an earlier commit)
                continue
            self._undo.append((holder, fn, original))
            setattr(holder, fn, self._wrap(original, label))
        self.phase_of = lambda: "setup"  # until the first episode's sink hands over its phases
        self._last = time.process_time()
        return self

    def __exit__(self, *exc: object) -> None:
        self._charge()
        for holder, fn, original in reversed(self._undo):
            setattr(holder, fn, original)
        self._undo.clear()

    def physics(self) -> tuple[float, int]:
        """(CPU s inside ``stepSimulation``, steps) over every phase."""
        return (sum(v for k, v in self.cpu.items() if k.startswith(PHYSICS)), sum(self.steps.values()))
