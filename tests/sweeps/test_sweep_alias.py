"""``tumble.sweep`` is the function :func:`tumble.sweeps.sweep`; the old spellings of the package it was keep
working until tumble 0.5, each with a DeprecationWarning that names its ``tumble.sweeps`` replacement.

Each spelling runs in a new Python process (``sys.executable``), since an import changes the process for good:
``import tumble.sweep`` first, as a script would, then the others.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

SPELLINGS = textwrap.dedent("""
    import json, sys, warnings

    def spelled(code):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            namespace = {}
            exec(code, namespace)
        return namespace.get("got"), [str(w.message) for w in caught if w.category is DeprecationWarning]

    results = {}
    got, said = spelled("import tumble.sweep\\nimport tumble\\ngot = tumble.sweep")
    import tumble, tumble.sweeps
    results["import tumble.sweep"] = [got is tumble.sweep and got.__wrapped__ is tumble.sweeps.sweep, said]
    try:
        tumble.sweep(tumble.RigidBody([[1.0, 0, 0], [0, 2.0, 0], [0, 0, 3.0]]), {}, samples=0, t=[0.0, 1.0])
    except tumble.ValidationError as error:  # refused by tumble.sweeps.sweep before anything runs
        results["tumble.sweep(...)"] = [str(error).startswith("samples: must be >= 1"), []]
    for code, new in [("import tumble\\ngot = tumble.sweep.Normal", tumble.sweeps.Normal),
                      ("from tumble.sweep import Grid as got", tumble.sweeps.Grid),
                      ("import tumble.sweep.store\\ngot = sys.modules['tumble.sweep.store']", tumble.sweeps.store),
                      ("from tumble.sweep.plan import make_plan as got", tumble.sweeps.plan.make_plan)]:
        got, said = spelled("import sys\\n" + code)
        results[code] = [got is new and callable(tumble.sweep), said]
    print(json.dumps(results))
""")

#: What each spelling warns: the old name and the new one.
RENAMED = {"import tumble\ngot = tumble.sweep.Normal": ("tumble.sweep.Normal", "tumble.sweeps.Normal"),
           "from tumble.sweep import Grid as got": ("tumble.sweep.Grid", "tumble.sweeps.Grid"),
           "import tumble.sweep.store\ngot = sys.modules['tumble.sweep.store']": ("tumble.sweep.store",
                                                                                   "tumble.sweeps.store"),
           "from tumble.sweep.plan import make_plan as got": ("tumble.sweep.plan", "tumble.sweeps.plan")}


def test_each_old_spelling_of_the_sweep_package_gives_the_new_name_with_a_deprecation_warning():
    out = subprocess.run([sys.executable, "-c", SPELLINGS], capture_output=True, text=True, timeout=120, check=True)
    results = json.loads(out.stdout.splitlines()[-1])
    assert results.pop("import tumble.sweep") == [True, []]  # the function, not rebound to a module; no warning
    assert results.pop("tumble.sweep(...)") == [True, []]
    assert results.keys() == RENAMED.keys()
    for code, (old, new) in RENAMED.items():
        same, said = results[code]
        assert same, code  # the very object of tumble.sweeps, and tumble.sweep still the function
        # `from tumble.sweep import X` warns twice, once for the import system's hasattr and once for X itself
        assert said and set(said) == {f"{old} is deprecated and will be removed in tumble 0.5: use {new}"}, code
