"""Seeing a run: a rerun recording (``--record``, ``--rerun``), a video (``--video``),
MuJoCo's viewer (``--viewer``) and the replay of a log (``dial replay``).

Each is an observer of the engine (:class:`dial.engine.Observer`): it reads the robot and
the log after each control period and never changes them, so a watched run gives the same
results as an unwatched one. Every rerun call is in :mod:`dial.recording.rerun_sink`.
"""
