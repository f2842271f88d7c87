"""Helpers shared by the tests."""

from tumble.integrate import METHODS


def read_by(method: str, **options) -> dict:
    """The solver ``options`` that ``method`` reads, with ``method`` itself (``simulate`` refuses the others)."""
    return {"method": method, **{k: v for k, v in options.items() if k in METHODS[method].options}}
