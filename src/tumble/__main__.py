"""``python -m tumble``: the ``tumble`` command (see :mod:`tumble.cli`)."""

from tumble.cli import app

app(prog_name="tumble")
