"""Compiled loops of the onset detector's modes' band and level band (:mod:`.onsets`' steps 4 and 5).

Each computes what the numpy or BLAS code it replaced did, to the bit: a product BLAS ran is run
here as OpenBLAS's kernel runs it (each entry's fused multiply-adds in row order), so that the
least-squares fits downstream see the same normal equations.
"""

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .._jit import jit

@intrinsic
def _gram_tile(typingctx, rows, width, count, i, j, gram):
    """``gram[i:i + 4, j:j + 8] += rows[:count, i:i + 4].T @ rows[:count, j:j + 8]`` (both C-contiguous, ``width``
    columns), each entry's products added by fused multiply-adds in row order from 0, as OpenBLAS's kernel adds them;
    the 32 sums in 8 vector registers (numba vectorises no loop whose sums must stay in order)."""
    sig = types.none(rows, width, count, i, j, gram)

    def codegen(context, builder, signature, args):
        rows_array = context.make_array(signature.args[0])(context, builder, args[0])
        gram_array = context.make_array(signature.args[5])(context, builder, args[5])
        width, count, i, j = (context.cast(builder, value, kind, types.intp)
                              for value, kind in zip(args[1:5], signature.args[1:5]))
        double = ir.DoubleType()
        vector = ir.VectorType(double, 4)
        fma = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vector, [vector] * 3), "llvm.fma.v4f64")
        zero = ir.Constant(vector, [0.0] * 4)
        sums = [[cgutils.alloca_once_value(builder, zero) for _ in range(2)] for _ in range(4)]

        def at(data, index):
            return builder.gep(data, [index])

        def load_vector(data, index):
            return builder.load(builder.bitcast(at(data, index), vector.as_pointer()), align=8)

        with cgutils.for_range(builder, count) as loop:
            row = builder.mul(loop.index, width)
            left = builder.add(row, i)
            right = builder.add(row, j)
            b = [load_vector(rows_array.data, right),
                 load_vector(rows_array.data, builder.add(right, ir.Constant(right.type, 4)))]
            for k in range(4):
                a = builder.load(at(rows_array.data, builder.add(left, ir.Constant(left.type, k))))
                a = builder.shuffle_vector(builder.insert_element(ir.Constant(vector, ir.Undefined), a,
                                                                  ir.Constant(ir.IntType(32), 0)),
                                           ir.Constant(vector, ir.Undefined), ir.Constant(ir.VectorType(ir.IntType(32), 4), [0] * 4))
                for h in range(2):
                    builder.store(builder.call(fma, [a, b[h], builder.load(sums[k][h])]), sums[k][h])
        for k in range(4):
            row = builder.mul(builder.add(i, ir.Constant(i.type, k)), width)
            for h in range(2):
                index = builder.add(builder.add(row, j), ir.Constant(j.type, 4 * h))
                pointer = builder.bitcast(at(gram_array.data, index), vector.as_pointer())
                builder.store(builder.fadd(builder.load(pointer, align=8), builder.load(sums[k][h])), pointer, align=8)
        return context.get_dummy_value()

    return sig, codegen


@jit
def weighted_gram(x, weight, order, block):
    """The normal equations ``Σ r r^T`` of the rows ``r = (x[n], x[n - 1], …, x[n - order]) weight[n]`` for ``n`` from
    ``order`` to ``len(x) - 1`` [shape=(order + 1, order + 1)].

    What numpy gave: each ``block`` of rows' product ``rows.T @ rows`` (OpenBLAS's) added to the sum in turn. The
    rows are formed (each product rounded) a block at a time, and only the upper triangle's products are taken (the
    lower's are the same: a fused multiply-add's two factors commute).
    """
    size = order + 1
    width = size + 7  # whole tiles from the diagonal on: the padding's columns stay 0 and its sums are not read
    rows = np.zeros((block, width))
    total = np.zeros((width, width))
    for start in range(order, len(x), block):
        count = min(len(x), start + block) - start
        for n in range(start, start + count):
            for k in range(size):
                rows[n - start, k] = x[n - k] * weight[n]
        for i in range(0, size, 4):
            for j in range(i, size, 8):
                _gram_tile(rows, width, count, i, j, total)
    gram = np.empty((size, size))
    for i in range(size):
        for j in range(i, size):
            gram[i, j] = gram[j, i] = total[i, j]
    return gram
