"""Executors: a run's episodes spread over local processes (:mod:`robocfg.executors.pool`) or Ray
actors (:mod:`robocfg.executors.ray_pool`), the same batches either way
(:mod:`robocfg.executors.session`), results and dataset shards merged into what one process
would produce."""
