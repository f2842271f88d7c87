"""The version of tumble: its one source, which ``pyproject.toml`` reads and ``tumble.__version__`` re-exports
(a module of its own, so that any module can read it without importing the package above it)."""

__version__ = "0.4.0"
