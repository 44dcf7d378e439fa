# SPDX-License-Identifier: BSD-3-Clause
"""Every class, method and property of the module says what it is (docs/reference/python.md)."""
import inspect

import mcopt


def own_text(doc):
    """A docstring without pybind11's generated signature lines."""
    lines = [l for l in (doc or "").splitlines() if l.strip()]
    return [l for l in lines if not (l.split("(")[0].strip().isidentifier() and ") ->" in l)
            and not l.strip()[0:2].isdigit() and not l.startswith("Overloaded")]


def test_every_public_name_has_a_docstring():
    missing = []
    assert own_text(mcopt.__doc__)
    for name, cls in inspect.getmembers(mcopt, inspect.isclass):
        if name.startswith("_") or issubclass(cls, BaseException):
            continue
        if not own_text(cls.__doc__):
            missing.append(name)
        for member, value in vars(cls).items():
            if member.startswith("_") and member not in ("__init__", "__getitem__", "__setitem__"):
                continue
            if not own_text(getattr(value, "__doc__", None)):
                missing.append(f"{name}.{member}")
    assert not missing, f"without a docstring: {missing}"


def test_input_error_is_a_value_error():
    assert issubclass(mcopt.InputError, ValueError)
