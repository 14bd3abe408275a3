"""Structure of arrays: a per-lane function re-expressed as elementwise operations on lane blocks.

`blockwise(fn, *examples)` traces ``fn`` once at the shapes of one lane (scalars, 3-vectors, the
13-vector state, ...) and returns a function of *lane blocks*: every array of the lane becomes a
numpy object array of its per-lane shape whose elements are either a block -- a JAX array of
shape (B,), one value per lane -- or a concrete number shared by all lanes. Every operation of
the traced program is then replayed element by element: small contractions (dot products,
3 x 3 matrix products) become explicit sums, slices and concatenations become numpy indexing of
the object arrays, and what depends on shared numbers alone (the inertia adjugate, the contact
law's constants) is computed once, at trace time. The result contains elementwise operations on
(B,) blocks only, which is what a GPU kernel of one thread per lane needs
(`jaxcelt.ensemble.kernel`): Pallas' Triton backend lowers elementwise arithmetic and loops,
not the small batched reductions and concatenations that `jax.vmap` of the per-lane function makes.

Primitives outside the supported set raise ``NotImplementedError`` naming the primitive.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["blockwise", "as_blocks", "from_blocks", "is_block"]

_ELEMENTWISE = frozenset(
    """abs acos acosh add add_any and asin asinh atan atan2 atanh bitcast_convert_type cbrt ceil clamp
    convert_element_type copy copy_p cos cosh div eq erf exp exp2 expm1 floor ge gt imag integer_pow
    is_finite le log log1p logistic lt max min mul ne neg nextafter not or pow real reduce_precision rem
    round rsqrt select_n shift_left shift_right_arithmetic shift_right_logical sign sin sinh sqrt square
    stop_gradient sub tan tanh xor""".split()
)
_CALLS = {"pjit": "jaxpr", "jit": "jaxpr", "closed_call": "call_jaxpr", "core_call": "call_jaxpr",
          "custom_jvp_call": "call_jaxpr", "custom_vjp_call": "call_jaxpr", "custom_vjp_call_jaxpr": "fun_jaxpr",
          "remat": "jaxpr", "checkpoint": "jaxpr"}  # fmt: skip


def is_block(x: Any) -> bool:
    """Whether an element is a per-lane block (a JAX array or tracer with a lane axis)."""
    return isinstance(x, jax.Array | jax.core.Tracer) and np.ndim(x) == 1


def as_blocks(x: Any) -> np.ndarray:
    """A (B, *shape) array of lanes as an object array of its per-lane shape, of (B,) blocks."""
    x = jnp.asarray(x)
    out = np.empty(x.shape[1:], dtype=object)
    for idx in np.ndindex(out.shape):
        out[idx] = x[(slice(None), *idx)]
    return out


def from_blocks(obj: np.ndarray, size: int, dtype: Any) -> jax.Array:
    """The inverse of `as_blocks`: an object array of blocks (or shared numbers) as (B, *shape)."""
    obj = np.asarray(obj, dtype=object)
    flat = [_broadcast(e, size, dtype) for e in obj.reshape(-1)]
    if not flat:
        return jnp.zeros((size, *obj.shape), dtype)
    return jnp.stack(flat, axis=-1).reshape(size, *obj.shape)


def _broadcast(e: Any, size: int, dtype: Any) -> jax.Array:
    if is_block(e):
        return e.astype(dtype) if e.dtype != dtype else e
    return jnp.full((size,), np.asarray(e), dtype=dtype)


def _concrete(x: Any) -> np.ndarray:
    return np.asarray(x)


def _apply(prim: Any, params: dict, elems: list[Any], dtypes: list[Any]) -> Any:
    """One elementwise primitive on scalars: folded when all are shared numbers, else on blocks."""
    size = next((int(e.shape[0]) for e in elems if is_block(e)), None)
    if size is None:
        with jax.ensure_compile_time_eval(), jax.default_device(jax.devices("cpu")[0]):
            out = prim.bind(*[jnp.asarray(e, dtype=d) for e, d in zip(elems, dtypes)], **params)
        return jax.tree_util.tree_map(_concrete, out)
    return prim.bind(*[_broadcast(e, size, d) for e, d in zip(elems, dtypes)], **params)


def _elementwise(eqn: Any, *xs: np.ndarray) -> list[np.ndarray]:
    prim = jax.lax.add_p if eqn.primitive.name == "add_any" else eqn.primitive  # a derivative's sum of tangents
    shapes = {x.shape for x in xs if x.shape != ()}
    shape = shapes.pop() if shapes else ()
    if shapes:
        raise NotImplementedError(f"{eqn.primitive.name}: operands of different shapes")
    xs = [np.broadcast_to(x, shape) for x in xs]
    dtypes = [v.aval.dtype for v in eqn.invars]
    nout = len(eqn.outvars) if eqn.primitive.multiple_results else 1
    outs = [np.empty(shape, dtype=object) for _ in range(nout)]
    for idx in np.ndindex(shape):
        r = _apply(prim, eqn.params, [x[idx] for x in xs], dtypes)
        for o, v in zip(outs, r if prim.multiple_results else [r]):
            o[idx] = v
    return outs


def _sum(terms: list[Any], add: Callable[[Any, Any], Any]) -> Any:
    out = terms[0]
    for t in terms[1:]:
        out = add(out, t)
    return out


def _dot_general(eqn: Any, lhs: np.ndarray, rhs: np.ndarray) -> list[np.ndarray]:
    (lc, rc), (lb, rb) = eqn.params["dimension_numbers"]
    dt = eqn.outvars[0].aval.dtype
    lf = [d for d in range(lhs.ndim) if d not in lc and d not in lb]
    rf = [d for d in range(rhs.ndim) if d not in rc and d not in rb]
    out_shape = tuple(lhs.shape[d] for d in lb) + tuple(lhs.shape[d] for d in lf) + tuple(rhs.shape[d] for d in rf)
    out = np.empty(out_shape, dtype=object)
    mul = lambda a, b: _apply(jax.lax.mul_p, {}, [a, b], [dt, dt])  # noqa: E731
    add = lambda a, b: _apply(jax.lax.add_p, {}, [a, b], [dt, dt])  # noqa: E731
    conv = lambda a, src: a if src == dt else _apply(  # noqa: E731
        jax.lax.convert_element_type_p, {"new_dtype": dt, "weak_type": False, "sharding": None}, [a], [src]
    )
    ldt, rdt = eqn.invars[0].aval.dtype, eqn.invars[1].aval.dtype
    for oidx in np.ndindex(out_shape):
        b, f1, f2 = oidx[: len(lb)], oidx[len(lb) : len(lb) + len(lf)], oidx[len(lb) + len(lf) :]
        terms = []
        for cidx in itertools.product(*[range(lhs.shape[d]) for d in lc]):
            li = [0] * lhs.ndim
            ri = [0] * rhs.ndim
            for d, i in zip(lb, b):
                li[d] = i
            for d, i in zip(rb, b):
                ri[d] = i
            for d, i in zip(lf, f1):
                li[d] = i
            for d, i in zip(rf, f2):
                ri[d] = i
            for dl, dr, i in zip(lc, rc, cidx):
                li[dl] = i
                ri[dr] = i
            terms.append(mul(conv(lhs[tuple(li)], ldt), conv(rhs[tuple(ri)], rdt)))
        out[oidx] = _sum(terms, add) if terms else np.zeros((), dt)
    return [out]


def _reduce(op: Any) -> Callable[..., list[np.ndarray]]:
    def rule(eqn: Any, x: np.ndarray) -> list[np.ndarray]:
        axes = tuple(eqn.params["axes"])
        dt = eqn.outvars[0].aval.dtype
        keep = [d for d in range(x.ndim) if d not in axes]
        moved = np.moveaxis(x, keep, list(range(len(keep)))) if keep else x
        out_shape = moved.shape[: len(keep)]
        out = np.empty(out_shape, dtype=object)
        for idx in np.ndindex(out_shape):
            terms = list(np.asarray(moved[idx], dtype=object).reshape(-1))
            out[idx] = _sum(terms, lambda a, b: _apply(op, {}, [a, b], [dt, dt]))
        return [out]

    return rule


def _broadcast_in_dim(eqn: Any, x: np.ndarray) -> list[np.ndarray]:
    shape, dims = eqn.params["shape"], eqn.params["broadcast_dimensions"]
    expanded = [1] * len(shape)
    for src, d in enumerate(dims):
        expanded[d] = x.shape[src]
    return [np.array(np.broadcast_to(x.reshape(expanded), shape), dtype=object)]


def _iota(eqn: Any) -> list[np.ndarray]:
    p = eqn.params
    a = np.arange(p["shape"][p["dimension"]], dtype=p["dtype"])
    idx = [None] * len(p["shape"])
    idx[p["dimension"]] = slice(None)
    return [_as_object(np.broadcast_to(a[tuple(idx)], p["shape"]))]


_STRUCTURAL: dict[str, Callable[..., list[np.ndarray]]] = {
    "slice": lambda e, x: [x[tuple(slice(s, l, st) for s, l, st in zip(
        e.params["start_indices"], e.params["limit_indices"], e.params["strides"] or [1] * x.ndim))]],
    "squeeze": lambda e, x: [np.squeeze(x, axis=tuple(e.params["dimensions"])) if x.ndim else x],
    "reshape": lambda e, x: [x.reshape(e.params["new_sizes"])],
    "expand_dims": lambda e, x: [np.expand_dims(x, e.params["dimensions"])],
    "concatenate": lambda e, *xs: [np.concatenate(xs, axis=e.params["dimension"])],
    "stack": lambda e, *xs: [np.stack(xs, axis=e.params["axis"])],
    "transpose": lambda e, x: [np.transpose(x, e.params["permutation"])],
    "rev": lambda e, x: [np.flip(x, axis=tuple(e.params["dimensions"]))],
    "broadcast_in_dim": _broadcast_in_dim,
    "dot_general": _dot_general,
    "reduce_sum": _reduce(jax.lax.add_p),
    "reduce_max": _reduce(jax.lax.max_p),
    "reduce_min": _reduce(jax.lax.min_p),
    "reduce_and": _reduce(jax.lax.and_p),
    "reduce_or": _reduce(jax.lax.or_p),
    "iota": _iota,
}  # fmt: skip


def _as_object(x: Any) -> np.ndarray:
    x = np.asarray(x)
    out = np.empty(x.shape, dtype=object)
    for idx in np.ndindex(x.shape):
        out[idx] = x[idx]
    return out


def _leaf(x: Any) -> np.ndarray:
    """An argument leaf as an object array: object arrays as they are, a lone block as a scalar."""
    if isinstance(x, np.ndarray) and x.dtype == object:
        return x
    if is_block(x):
        out = np.empty((), dtype=object)
        out[()] = x
        return out
    return _as_object(x)


def _eval(jaxpr: Any, consts: list[Any], args: list[np.ndarray]) -> list[np.ndarray]:
    env: dict[Any, np.ndarray] = {}

    def read(v: Any) -> np.ndarray:
        if isinstance(v, jax.extend.core.Literal):
            return _as_object(v.val)
        return env[v]

    for v, c in zip(jaxpr.constvars, consts):
        env[v] = c if isinstance(c, np.ndarray) and c.dtype == object else _as_object(c)
    for v, a in zip(jaxpr.invars, args):
        env[v] = a
    for eqn in jaxpr.eqns:
        name = eqn.primitive.name
        invals = [read(v) for v in eqn.invars]
        if name in _CALLS:
            closed = eqn.params[_CALLS[name]]
            inner, inner_consts = (closed.jaxpr, closed.consts) if hasattr(closed, "consts") else (closed, [])
            outs = _eval(inner, list(inner_consts), invals)
        elif name in _ELEMENTWISE:
            outs = _elementwise(eqn, *invals)
        elif name in _STRUCTURAL:
            outs = _STRUCTURAL[name](eqn, *invals)
        else:
            raise NotImplementedError(f"blockwise: primitive {name!r} is not supported")
        for v, o in zip(eqn.outvars, outs):
            env[v] = np.asarray(o, dtype=object) if not isinstance(o, np.ndarray) else o
    return [read(v) for v in jaxpr.outvars]


def blockwise(fn: Callable[..., Any], *examples: Any) -> Callable[..., Any]:
    """``fn`` (a function of one lane) as a function of lane blocks (module docstring).

    ``examples``: arguments of one lane (their shapes and dtypes are what is traced; their
    values are not used). The returned function takes arguments of the same tree structure whose
    leaves are object arrays of the per-lane shapes (`as_blocks`), with (B,) blocks or shared
    numbers as elements, and returns ``fn``'s output tree with such leaves."""
    closed = jax.make_jaxpr(fn)(*examples)
    out_tree = jax.tree_util.tree_structure(jax.eval_shape(fn, *examples))
    in_tree = jax.tree_util.tree_structure(examples)

    def run(*args: Any) -> Any:
        leaves, tree = jax.tree_util.tree_flatten(args, is_leaf=lambda x: isinstance(x, np.ndarray))
        if tree != in_tree:
            raise ValueError(f"blockwise: arguments of structure {tree}, traced with {in_tree}")
        leaves = [_leaf(x) for x in leaves]
        outs = _eval(closed.jaxpr, list(closed.consts), leaves)
        return jax.tree_util.tree_unflatten(out_tree, outs)

    return run
