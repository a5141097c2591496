"""Extrinsic dexterity: grasps of an object, regrasp actions, the grasp graph."""
