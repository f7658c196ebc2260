"""The package's version, in a module of its own so that every layer may name it without importing the package's face."""

__version__ = "0.2.0"
