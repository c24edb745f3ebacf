"""volviz: accurate, fast volume rendering of scientific data and natural scenes (Qt-free core library)."""
__version__ = "0.1.0"
