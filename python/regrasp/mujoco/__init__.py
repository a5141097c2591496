"""Execution in MuJoCo: the models (``model``), one push in the planner's view (``push``), planar
plans in the world's view (``planar``) and 3-D plans (``spatial``)."""
