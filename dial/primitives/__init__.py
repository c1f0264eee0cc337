"""What runs the instructions of DESIGN 3 on a robot, each a step object of its own.

Each instruction's record (:mod:`dial.instructions`) makes its primitive or sensor: the arm
motions (:mod:`dial.primitives.arm`), the hand's (:mod:`dial.primitives.hand`), the guarded
move (:mod:`dial.primitives.guarded`) and sensing (:mod:`dial.primitives.sensing`). They read
their snapshot and the robot's read-only view, and write only through their slots
(:mod:`dial.primitives.context`).
"""

from dial.primitives.context import Context

__all__ = ["Context"]
