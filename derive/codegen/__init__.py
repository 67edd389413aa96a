"""Emit the derived model as C99, one job per module.

- `spec`: the description of one kernel (name, inputs, outputs, docs);
- `kernels`: WHAT is emitted, the declarative list of kernels;
- `joint_first`: the model-specific joint-first solve of M ν̇ = f (symbolic system and its C);
- `constant_pool`: parameter-only subexpressions moved into sr_gen_constants;
- `c_printer`: generic C printing (literals, common factors, latency scheduler, flop counts);
- `emit`: kernel -> C text, the header and source texts, and `write`, the one place that writes files.

The hand-written part of the generated header (the scalar type `sr_real`,
SR_C, SR_GEN_PIVOT_TOL, the SR_GEN_ status codes) is c/include/sr_real.h, not a
Python string.
"""
