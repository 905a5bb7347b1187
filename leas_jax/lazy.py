"""Lazy package attributes (PEP 562): `import leas_jax.<package>` stays cheap.

A package lists `{attribute: module}` and gets a module `__getattr__` that imports the
module on first use and caches the attribute in the package. The command line builds
its parser from the packages' `commands` modules without starting JAX or Brax this way
(tests/test_cli.py checks it).
"""

from __future__ import annotations

import importlib


def lazy_getattr(package: str, namespace: dict, attributes: dict[str, str]):
    """A module `__getattr__` for `package` resolving `attributes` ({name: module name}).

    Args:
        package: the package's `__name__` (for the error message).
        namespace: the package's `globals()`, where resolved attributes are cached.
        attributes: {attribute name: dotted module that defines it, or "module:name"
            for an alias of another name}.
    """

    def __getattr__(name: str):
        if name not in attributes:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, source = attributes[name].partition(":")
        value = getattr(importlib.import_module(module), source or name)
        namespace[name] = value
        return value

    return __getattr__
