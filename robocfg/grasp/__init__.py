"""Grasp planning from simulated depth: camera, point cloud, gripper box model, antipodal sampling, quality."""
