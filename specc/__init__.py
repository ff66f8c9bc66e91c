"""specc: a declarative-spec compiler for autonomous-robot control architectures."""

__version__ = "0.1.0"
