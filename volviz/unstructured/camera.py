"""The camera lives in ``volviz.model.camera`` (the bottom layer, shared by every renderer); this name is kept for
the modules and programs that import it from here."""
from volviz.model.camera import *  # noqa: F401,F403
from volviz.model.camera import Camera, RayBasis  # noqa: F401
