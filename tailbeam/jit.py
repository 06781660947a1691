"""The decorator of every compiled kernel: numba's ``njit``, compiling one copy per argument type.

Numba types a constant argument by its value (``Literal[int](0)``, ``Literal[bool](True)``)
and an ``IntEnum`` member by its enum, and compiles the callee once more for each such type:
a helper called with ``0`` in one place and with a variable ``i`` in another is compiled
twice, and an event helper called with ``EventCode`` members and with plain integers up to
four times. Functions decorated here are typed with the plain types (``int64``, ``bool``)
when compiled code calls them, so one copy serves every call. On a fresh cache this cuts the
first compilation of the rigid, stream and coupled kernels by a quarter to a third (16 to
11 s, 64 to 48 s and 73 to 49 s of wall time at a load of 1, ``tools/time_revisions.py``);
results are unchanged (the same operations on the path taken) and so is the run time
within the machine's noise.

A function whose body needs a constant argument (for example to index a heterogeneous
tuple) still gets it: if the plain types do not compile, numba's own typing is used.
"""

from numba import njit as _numba_njit
from numba.core import errors, types

__all__ = ["njit"]


def njit(function=None, **options):
    """``numba.njit(**options)``, with calls from compiled code typed by plain types.

    Parameters
    ----------
    function : callable, optional
        The function to compile; absent, a decorator is returned (``@njit(cache=True)``).
    **options
        numba's ``njit`` options (``cache``, ``inline``, ...).
    """
    if function is None:
        return lambda f: njit(f, **options)
    return _plain_calls(_numba_njit(**options)(function))


def _plain(argument_type):
    """The type numba would give a variable holding such a value: no literal, no enum."""
    plain = types.unliteral(argument_type)
    if isinstance(plain, types.IntEnumMember):
        return plain.dtype
    return plain


def _plain_calls(dispatcher):
    """Make calls from compiled code resolve ``dispatcher`` with plain argument types."""
    typed_by_value = dispatcher.get_call_template

    def get_call_template(args, kws):
        try:
            plain_kws = {name: _plain(t) for name, t in kws.items()}
            return typed_by_value(tuple(_plain(t) for t in args), plain_kws)
        except errors.TypingError:
            return typed_by_value(args, kws)

    dispatcher.get_call_template = get_call_template
    return dispatcher
