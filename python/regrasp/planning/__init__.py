"""Regrasp planning: the T-RRT* planner's entry point and the plan files (``plan``)."""
