"""Moved: the CLI's error path is :mod:`tumble.cli.errors`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, dict.fromkeys(("EXIT_BUG", "EXIT_ERROR", "exit_codes"), "tumble.cli.errors"))
