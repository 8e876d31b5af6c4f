"""Global motion planning in joint space: collision checking against the robot's collision model
and the scene (:mod:`.checker`), OMPL RRT-Connect (:mod:`.rrt`), path shortening
(:mod:`.shortcut`) and the planner that puts them together and times the result (:mod:`.planner`).

Importing this package imports neither pinocchio nor OMPL; building a checker or planning does.
"""

from robocfg.planning.planner import JointPlanner, PlannedPath, PlannerSettings, PlanningFailed

__all__ = ["JointPlanner", "PlannedPath", "PlannerSettings", "PlanningFailed"]
