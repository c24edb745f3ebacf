"""Dataset readers. Every reader raises ``volviz.io.ReadError`` (naming the file and the problem) on bad input."""
from volviz.io.errors import NonFiniteWarning, ReadError

__all__ = ["NonFiniteWarning", "ReadError"]
