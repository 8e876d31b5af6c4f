"""First module a process-pool fork server imports: pybullet without its build banner (the fork
server's other preloads import it, and the banner would land in the user's terminal)."""

from robocfg.sim.quiet import quiet_import

quiet_import()
