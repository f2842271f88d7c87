"""The ``tumble`` command: run scenario files and the demos, inspect and view results (``docs/cli.md``).

:mod:`.main` is the app and its commands ``run``, ``info``, ``view`` and ``examples``; :mod:`.demo`,
:mod:`.sweep`, :mod:`.cache` and :mod:`.robot` hold the other command groups; :mod:`.errors` is the one error
path (exit codes, one ``error:`` line per problem); :mod:`.common` what the commands share.
"""

from tumble.cli.main import app

__all__ = ["app"]
