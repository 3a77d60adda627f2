r"""Call a compiled numba function through its machine-code address, from compiled code.

Why: a numba function that calls another compiled function links a copy of the callee's LLVM
IR into its own module and optimises and compiles that copy again. For a small wrapper around a
big kernel (the Gymnasium environments' threaded step, a ``prange`` over ranges of lanes, each
running the one-call step of :mod:`steerlab.jit.env_template`) that repeats the kernel's whole
compile: seconds per (ship, guidance) pair. Calling the callee's machine code through its
address instead, the wrapper compiles in a fraction of a second and the callee's code is the
one already compiled (or loaded from the cache), so the numbers are those of a direct call.

:func:`call_at` (a numba intrinsic, usable only in compiled code) calls the function at an
address with numba's own calling convention; :func:`address_of` (Python) gives the address of a
dispatcher's compiled overload for given argument types. numba's first-class functions
(``types.FunctionType``) do the same but look the address up from Python on every call
(about 10-20 us, more than a threaded step's hand-over is worth).

The caller guarantees that the argument types at the :func:`call_at` site are those the
address was taken for (:func:`address_of` takes them from the very arguments the compiled caller
receives); a mismatch is undefined behaviour, as with any function pointer.
"""

from __future__ import annotations

from typing import Any

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def call_at(typingctx, address, args):
    """``f(*args)`` for the compiled numba function ``f`` at ``address`` (int64, from
    :func:`address_of`), returning its int64 result; ``args`` a tuple. An exception raised by
    ``f`` propagates to the caller."""
    if not isinstance(address, types.Integer) or not isinstance(args, types.BaseTuple):
        return None
    argtys = tuple(args.types)
    sig = types.int64(address, args)

    def codegen(context, builder, signature, llargs):
        addr, tup = llargs
        fnty = context.call_conv.get_function_type(types.int64, argtys)
        callee = builder.inttoptr(addr, fnty.as_pointer())
        values = cgutils.unpack_tuple(builder, tup, len(argtys))
        status, result = context.call_conv.call_function(builder, callee, types.int64, argtys, values)
        with cgutils.if_unlikely(builder, status.is_error):
            context.call_conv.return_status_propagate(builder, status)
        return result

    return sig, codegen


def address_of(dispatcher: Any, argtypes: tuple) -> int:
    """The machine-code address of ``dispatcher``'s overload for the numba types ``argtypes``
    (compiled, or loaded from numba's cache, first if needed); its return type must be int64
    (what :func:`call_at` reads). The dispatcher keeps the code alive: keep it referenced."""
    dispatcher.compile(tuple(argtypes))
    cres = dispatcher.overloads[tuple(argtypes)]
    if types.unliteral(cres.signature.return_type) != types.int64:
        raise TypeError(f"{dispatcher.py_func.__name__} returns {cres.signature.return_type}, call_at reads int64")
    return int(cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name))
