"""First module a process-pool fork server imports: one math-library thread for it and its workers
(before numpy is imported: :mod:`robocfg.executors.worker_setup`), and pybullet without its build
banner (the fork server's other preloads import it, and the banner would land in the user's
terminal), and with the start-up code cache installed (:mod:`robocfg.startcache`: the other
preloads create most of a worker's dataclasses; the forked workers inherit the cache and save it
once their world is built)."""

from robocfg import startcache
from robocfg.executors.worker_setup import single_threaded_env
from robocfg.sim.quiet import quiet_import

startcache.install()
single_threaded_env()
quiet_import()
