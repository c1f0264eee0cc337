"""Teaching and the world model: ``dial teach`` (jog, limp, save poses and locations into a
world file) and ``dial world`` (a scene's names as text, and a picture of its frames).

See ``docs/teaching.md``.
"""

from dial.teach.app import teach, world

__all__ = ["teach", "world"]
