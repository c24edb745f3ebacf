"""The error of a session that cannot be shown (raised by the scene layer and by ``volviz.render``)."""
from __future__ import annotations


class SceneError(Exception):
    """A session that cannot be shown: names the component and the problem."""
