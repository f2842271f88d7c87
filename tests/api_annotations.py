"""The public functions and methods of src/tumble that lack annotations (read from the source, not imported).

Public: a function or method (``__init__`` and ``__call__`` included, other dunders not) defined at the top
level of a module, or in a class there, whose module's dotted path has no component starting with ``_``, outside
``tumble.kernels`` (the Numba kernels), and whose own name (and its class's) does not start with ``_``.
Nested functions and ``@overload`` signatures do not count. Complete: a return annotation and one on every parameter, ``*args`` and
``**kwargs`` included, ``self``/``cls`` excepted.

Run ``python tests/api_annotations.py`` for the count and the list; tests/test_package.py asserts the list is
empty.
"""

from __future__ import annotations

import ast
import sys
from collections.abc import Iterator
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def _module_name(path: Path, src: Path) -> str:
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_public_module(name: str) -> bool:
    parts = name.split(".")
    return not any(p.startswith("_") for p in parts) and parts[:2] != ["tumble", "kernels"]


def _is_public_name(name: str) -> bool:
    if name in ("__init__", "__call__"):
        return True
    return not name.startswith("_")


def _is_overload(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    """An ``@overload`` signature: a declaration of the function defined after it, not one of its own."""
    return any((isinstance(d, ast.Name) and d.id == "overload") or (isinstance(d, ast.Attribute) and d.attr == "overload")
               for d in node.decorator_list)


def _functions(body: list[ast.stmt], prefix: str, in_class: bool) -> Iterator[tuple[str, ast.FunctionDef | ast.AsyncFunctionDef, bool]]:
    """(qualified name, node, is a method) of the functions and classes' methods in a module or class body."""
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if _is_public_name(node.name) and not _is_overload(node):
                yield f"{prefix}.{node.name}", node, in_class
        elif isinstance(node, ast.ClassDef):
            if not node.name.startswith("_"):
                yield from _functions(node.body, f"{prefix}.{node.name}", True)
        elif isinstance(node, ast.If):
            yield from _functions(node.body + node.orelse, prefix, in_class)
        elif isinstance(node, ast.Try):
            yield from _functions(node.body + node.orelse + node.finalbody, prefix, in_class)
            for handler in node.handlers:
                yield from _functions(handler.body, prefix, in_class)
        elif isinstance(node, ast.With):
            yield from _functions(node.body, prefix, in_class)


def _missing(node: ast.FunctionDef | ast.AsyncFunctionDef, is_method: bool) -> list[str]:
    """What a function lacks: 'return' and the names of its unannotated parameters."""
    args = node.args
    positional = args.posonlyargs + args.args
    static = any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list)
    if is_method and not static and positional:
        positional = positional[1:]  # self or cls
    missing = [a.arg for a in positional + args.kwonlyargs if a.annotation is None]
    if args.vararg is not None and args.vararg.annotation is None:
        missing.append("*" + args.vararg.arg)
    if args.kwarg is not None and args.kwarg.annotation is None:
        missing.append("**" + args.kwarg.arg)
    if node.returns is None:
        missing.append("return")
    return missing


def public_functions(src: Path = SRC) -> dict[str, list[str]]:
    """Every public function of the package, with what its annotations lack (an empty list: complete)."""
    found: dict[str, list[str]] = {}
    for path in sorted((src / "tumble").rglob("*.py")):
        module = _module_name(path, src)
        if not _is_public_module(module):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for name, node, is_method in _functions(tree.body, module, False):
            # a property's setter, or a function defined twice under an `if`, keeps the first key unique
            key = name if name not in found else f"{name}:{node.lineno}"
            found[key] = _missing(node, is_method)
    return found


def unannotated(src: Path = SRC) -> dict[str, list[str]]:
    """The public functions whose annotations are incomplete, with what each lacks."""
    return {name: lacks for name, lacks in public_functions(src).items() if lacks}


def main() -> int:
    every = public_functions()
    lacking = {name: lacks for name, lacks in every.items() if lacks}
    for name, lacks in lacking.items():
        print(f"{name}: {', '.join(lacks)}")
    print(f"{len(every) - len(lacking)} of {len(every)} public functions fully annotated; {len(lacking)} lacking")
    return 1 if lacking else 0


if __name__ == "__main__":
    sys.exit(main())
