"""The compiler pipeline of the chain kernels: the model's pieces (literal arguments, see
:mod:`stickslip.kernels.entry`) become constants before numba prunes dead branches, so a
composition's kernel is typed, inlined and lowered without the code of the other pieces.

numba prunes a branch on a constant (``if drive == DRIVE_PLATE``) before inlining and typing,
but it does not read the value of a literal argument there; without this pass every branch of
every piece is typed and lowered (compiling the functions it calls) and only then removed by
LLVM. The machine code is the same; the first compilation of a model takes less time (measured).
"""

from __future__ import annotations

from numba.core import ir, types
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_machinery import FunctionPass, register_pass
from numba.core.ir_utils import build_definitions
from numba.core.untyped_passes import FixupArgs


@register_pass(mutates_CFG=False, analysis_only=False)
class PiecesAsConstants(FunctionPass):
    """Replace each integer literal argument by its value in the function's IR."""

    _name = "stickslip_pieces_as_constants"

    def __init__(self):
        FunctionPass.__init__(self)

    def run_pass(self, state):
        changed = False
        for block in state.func_ir.blocks.values():
            for stmt in block.find_insts(ir.Assign):
                if isinstance(stmt.value, ir.Arg):
                    ty = state.args[stmt.value.index]
                    if isinstance(ty, types.IntegerLiteral):
                        stmt.value = ir.Const(ty.literal_value, stmt.value.loc)
                        changed = True
        if changed:
            # A new IR from the edited blocks, with the table of definitions that numba's later
            # passes read (built as numba's interpreter builds it); the post-processing that
            # follows in IRProcessing works on this one.
            fir = state.func_ir
            state.func_ir = ir.FunctionIR(
                fir.blocks,
                fir.is_generator,
                fir.func_id,
                fir.loc,
                build_definitions(fir.blocks),
                fir.arg_count,
                fir.arg_names,
            )
        return changed


class PiecesCompiler(CompilerBase):
    """numba's nopython pipeline with :class:`PiecesAsConstants` after its bytecode translation,
    before the IR's post-processing and branch pruning."""

    def define_pipelines(self):
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        pm.add_pass_after(PiecesAsConstants, FixupArgs)
        pm.finalize()
        return [pm]
