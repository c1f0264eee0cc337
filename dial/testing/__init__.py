"""Test helpers: a fake robot on virtual time, fake primitives, and a one-call runner.

Use them to test scheduling without physics::

    from dial.testing import Behaviour, run_fake

    result = run_fake(text, tick=0.25, behaviours={"grab": Behaviour(duration=0.6)})
    assert result.ends("grab") == [(3, 1.1)]
"""

from dial.testing.fake import Behaviour, FakeFactory, FakeResult, FakeRobot, run_fake

__all__ = ["Behaviour", "FakeFactory", "FakeResult", "FakeRobot", "run_fake"]
