"""Teaching and the world model: ``dial teach`` (jog, limp, save poses and locations into a
world file) and ``dial world`` (a scene's names as text, and a picture of its frames).

The entry points are in :mod:`dial.teach.app`; this package's root imports nothing, so that
the command line can read the command table (:mod:`dial.teach.commands`) without MuJoCo.
See ``docs/teaching.md``.
"""
