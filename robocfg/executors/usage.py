"""A process's resource use over a span (an episode), from ``getrusage``: what a benchmark needs
to tell why episodes cost more CPU when every core is busy (system time, page faults, being
switched out) apart from slower cores."""

from __future__ import annotations

import resource
from dataclasses import dataclass


@dataclass(frozen=True)
class Usage:
    """Resource use of this process (every thread): ``user`` and ``system`` CPU time (s), minor and
    major page faults, voluntary and involuntary context switches (counts). Taken with
    :meth:`now`; the difference of two is the use between them."""

    user: float = 0.0
    system: float = 0.0
    minflt: int = 0
    majflt: int = 0
    nvcsw: int = 0
    nivcsw: int = 0

    @classmethod
    def now(cls) -> Usage:
        r = resource.getrusage(resource.RUSAGE_SELF)
        return cls(r.ru_utime, r.ru_stime, r.ru_minflt, r.ru_majflt, r.ru_nvcsw, r.ru_nivcsw)

    def __sub__(self, other: Usage) -> Usage:
        return Usage(self.user - other.user, self.system - other.system, self.minflt - other.minflt,
                     self.majflt - other.majflt, self.nvcsw - other.nvcsw, self.nivcsw - other.nivcsw)


def thread_count() -> int:
    """Threads of this process now (Linux ``/proc``; 0 where unknown)."""
    import os

    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return 0
