"""Robots as folders: an MJCF, a ``robot.toml`` profile and a provenance README.

:mod:`dial.robots.profile` reads a profile (pure Python), :mod:`dial.robots.check` validates a
folder against its MJCF (``dial robots check``), :mod:`dial.robots.bundled` lists the bundled
robots (``dial robots``). The format, key by key: ``docs/robots.md``.
"""
