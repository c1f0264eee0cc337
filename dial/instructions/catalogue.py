"""The instruction set (DESIGN 3): every instruction, each declared in its own module.

To see how an instruction is declared, checked, run and previewed, open its module: its
:class:`~dial.instructions.base.Instruction` (name, length, parameters, usage) and its
argument record (an :class:`~dial.instructions.base.Args` subclass: effectors, check,
primitive or sensor, preview). The checker binds definitions against this table.
"""

from __future__ import annotations

from dial.instructions.arm_move import ARM_MOVE
from dial.instructions.base import Instruction
from dial.instructions.contact import FORCE_CONTACT, POSITION_CONTACT, TACTILE_CONTACT
from dial.instructions.finger_move import FINGER_MOVE
from dial.instructions.fit import FIT_PLANE, FIT_SUPERQUADRIC
from dial.instructions.get import GET_FORCES, GET_JOINTS, GET_TACTILE, GET_WRIST
from dial.instructions.grasp_force import GRASP_FORCE
from dial.instructions.guarded_move import GUARDED_MOVE
from dial.instructions.hand_pose import HAND_POSE
from dial.instructions.limp import LIMP
from dial.instructions.locate import LOCATE
from dial.instructions.puma_command import PUMA_COMMAND
from dial.instructions.record_contact import RECORD_CONTACT

INSTRUCTIONS: dict[str, Instruction] = {
    i.name: i
    for i in (
        GET_JOINTS,  # get.py
        GET_FORCES,
        GET_TACTILE,
        GET_WRIST,
        HAND_POSE,  # hand_pose.py
        FINGER_MOVE,  # finger_move.py
        PUMA_COMMAND,  # puma_command.py
        ARM_MOVE,  # arm_move.py
        POSITION_CONTACT,  # contact.py
        FORCE_CONTACT,
        TACTILE_CONTACT,
        GRASP_FORCE,  # grasp_force.py
        GUARDED_MOVE,  # guarded_move.py
        LIMP,  # limp.py
        RECORD_CONTACT,  # record_contact.py
        LOCATE,  # locate.py
        FIT_PLANE,  # fit.py
        FIT_SUPERQUADRIC,
    )
}

# The instructions whose condition holds or not at each moment, so that a monitor can sense
# it every control period: the contact conditions (DESIGN 2.7).
WATCHABLE = tuple(name for name, i in INSTRUCTIONS.items() if i.condition is not None)
