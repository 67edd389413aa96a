#!/usr/bin/env python3
"""Flash, RAM and stack of the float library on a Cortex-M4F, at -Os and -O2.

    python3 tools/m4_report.py [--build DIR]                 # print the Markdown
    python3 tools/m4_report.py --update docs/embedding.md    # also `make cross-report` in c/

Three parts (docs/embedding.md, "Cortex-M targets"):

1. Per function: tools/size_report.py's method on arm-none-eabi objects (-ffunction-sections
   -fstack-usage -fcallgraph-info=su): own code and code with every library function it reaches
   (flash), own frame and worst case through the call graph (stack; libm outside, counted 0).
   The library has no static RAM (no .data or .bss: tests/test_c_library.py), so the RAM a call
   needs is its stack plus the caller's model and arrays.
2. A Lie-Euler-only firmware (c/cross/lie_euler_firmware.c: sr_model_init, sr_check_state, sr_accel and
   a Lie-Euler step per tick) linked with --gc-sections for the mps2-an386: flash and RAM by
   origin (library, libm, libgcc, newlib and semihosting, start-up and main), from the linker
   map; the image is checked for software double routines (__aeabi_d*: a failure).
3. The same image run under QEMU: the stack each entry point really used (libm included),
   measured by painting.

Exit status 1 if a build or run fails or a double routine is linked.  The 8 KB flash and 1 KB
stack targets are reported, met or not, but do not fail the run.
"""
import argparse
import concurrent.futures
import os
import pathlib
import re
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import size_report  # noqa: E402  (tools/size_report.py: sources, compile, call graph)

CROSS = size_report.C_DIR / "cross"   # the start-up file, the linker scripts, the firmware

CPU_FLAGS = ["-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard"]
LEVELS = ("-O2", "-Os")
BEGIN, END = "<!-- m4-report:begin -->", "<!-- m4-report:end -->"
FLASH_TARGET, STACK_TARGET = 8192, 1024   # flash: accel + Lie-Euler step; stack: Lie-Euler step
SOFT_DOUBLE = re.compile(r"^__aeabi_(d|[fil]2d|ui2d|ul2d)")
# Entry points of a Lie-Euler firmware, by the symbol the float build gives them.
LIE_EULER_ENTRY = "sr_step_f"      # the per-method entry point once it exists (see lie_euler_step)
ACCEL_ENTRY = "sr_accel_f"


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw).stdout


def lie_euler_step(lib):
    """The Lie-Euler step's symbol: sr_step_lie_euler_f where the library has it, else sr_step_f."""
    return "sr_step_lie_euler_f" if "sr_step_lie_euler_f" in lib.nodes else LIE_EULER_ENTRY


# ---- 1. per function -------------------------------------------------------------------------
def per_function(tools, build):
    libs = {}
    for opt in LEVELS:
        out = build / f"objs{opt}"
        out.mkdir(parents=True, exist_ok=True)
        objs = size_report.compile_variant(tools["cc"], CPU_FLAGS, opt, True, out)
        libs[opt] = size_report.Library(objs, tools["nm"])
    publics = [fn + "_f" for fn in size_report.public_functions()]
    internals = sorted(t for t in libs["-O2"].nodes if ":" not in t and t not in publics)
    lines = ["| function | flash -O2 | flash -Os | stack -O2 | stack -Os | libm calls |",
             "|---|---:|---:|---:|---:|---|"]
    for title in publics + [None] + internals:
        if title is None:
            lines.append("| *internal, called by the above:* | | | | | |")
            continue
        if not all(title in lib.nodes for lib in libs.values()):
            continue
        o2, os_ = libs["-O2"].row(title), libs["-Os"].row(title)
        ext = sorted(set(o2["external"]) | set(os_["external"]))
        lines.append(f"| `{title[:-2]}` | {o2['own']} / {o2['total']} | {os_['own']} / {os_['total']} "
                     f"| {o2['frame']} / {o2['worst']} | {os_['frame']} / {os_['worst']} "
                     f"| {', '.join(e.removesuffix('_f') if e.startswith('sr_') else e for e in ext) or '-'} |")
    # accel + a Lie-Euler step: the union of what the two reach, each function once; and the same
    # for the library built with -DSR_PAPER_ONLY (no general kernels: a paper-geometry firmware).
    union = {}
    for opt, lib in libs.items():
        step = lie_euler_step(lib)
        seen = lib.reachable(ACCEL_ENTRY)[0] | lib.reachable(step)[0]
        out = build / f"objs{opt}-paper-only"
        out.mkdir(parents=True, exist_ok=True)
        paper = size_report.Library(size_report.compile_variant(tools["cc"], [*CPU_FLAGS, "-DSR_PAPER_ONLY"], opt,
                                                                True, out), tools["nm"])
        paper_seen = paper.reachable(ACCEL_ENTRY)[0] | paper.reachable(step)[0]
        union[opt] = (sum(lib.size(t) for t in seen), lib.worst_stack(step), step,
                      sum(paper.size(t) for t in paper_seen), paper.worst_stack(step))
    return lines, union


# ---- 2. the Lie-Euler-only firmware ------------------------------------------------------------
def link_firmware(tools, build, opt):
    out = build / f"firmware{opt}"
    out.mkdir(parents=True, exist_ok=True)
    flags = [*CPU_FLAGS, opt, "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-ffp-contract=off",
             "-DSR_USE_FLOAT", "-Wdouble-promotion", "-Wfloat-conversion", "-ffunction-sections",
             "-fdata-sections", f"-I{size_report.INCLUDE}", f"-I{size_report.ROOT / 'generated'}"]
    def compile_one(src):
        obj = out / (src.stem + ".o")
        run([tools["cc"], *flags, "-c", str(src), "-o", str(obj)])
        return obj
    with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 1) as pool:
        objs = list(pool.map(compile_one, [*size_report.sources(), CROSS / "lie_euler_firmware.c",
                                            CROSS / "startup.c"]))
    elf, mapfile = out / "lie_euler_firmware.elf", out / "lie_euler_firmware.map"
    run([tools["cc"], *CPU_FLAGS, opt, *map(str, objs), f"-L{CROSS}", "-T", str(CROSS / "mps2-an386.ld"),
         "--specs=rdimon.specs", "-nostartfiles", "-Wl,--gc-sections", f"-Wl,-Map={mapfile}", "-lm",
         "-o", str(elf)])
    library_objects = {o.name for o in objs[:len(size_report.sources())]}
    return elf, mapfile, library_objects


def origin(path, library_objects):
    name = pathlib.Path(path.split("(")[0]).name
    if name in library_objects:
        return "library"
    if name in ("libm.a", "libgcc.a"):
        return name.removesuffix(".a")
    if name in ("libc.a", "librdimon.a", "libg.a"):
        return "newlib + semihosting"
    return "start-up + main"


def map_sizes(mapfile, library_objects):
    """{origin: [flash, ram]} from a GNU ld map: input sections under each output section."""
    totals = {}
    text = mapfile.read_text().split("Linker script and memory map", 1)[1]
    out_section, pending = None, None
    for line in text.splitlines():
        m = re.match(r"^(\.[\w.]+)(?:\s+0x[0-9a-f]+\s+0x[0-9a-f]+(?: load address 0x[0-9a-f]+)?)?\s*$", line)
        if m:
            out_section, pending = m.group(1), None
            continue
        m = re.match(r"^ (\.[\w.$]+|COMMON)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (?:(\.[\w.$]+|COMMON))?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$", line)
        if m and (m.group(1) or pending) and out_section in (".text", ".ARM.exidx", ".ARM.extab", ".data", ".bss"):
            size = int(m.group(3), 16)
            cell = totals.setdefault(origin(m.group(4), library_objects), [0, 0])
            if out_section in (".data", ".bss"):
                cell[1] += size
            if out_section != ".bss":
                cell[0] += size   # .data's initial values sit in flash too
        pending = None
    return totals


def measure_stack(tools, elf):
    out = subprocess.run([tools["qemu"], "-M", "mps2-an386", "-nographic", "-monitor", "none", "-serial",
                          "none", "-semihosting-config", "enable=on,target=native", "-kernel", str(elf)],
                         capture_output=True, text=True, timeout=300)
    if out.returncode != 0:
        sys.exit(f"m4_report: {elf} exited with {out.returncode}: {out.stdout}{out.stderr}")
    stacks = {}
    for line in out.stdout.splitlines():
        parts = line.split()
        if parts[:1] == ["stack"]:
            stacks[parts[1]] = int(parts[2])
    if not stacks or "ticks 100" not in out.stdout:
        sys.exit(f"m4_report: unexpected output of {elf}: {out.stdout}")
    return stacks


def firmware(tools, build):
    rows, stacks, images, failures = {}, {}, {}, []
    for opt in LEVELS:
        elf, mapfile, library_objects = link_firmware(tools, build, opt)
        soft = sorted({s.split()[-1] for s in run([tools["nm"], str(elf)]).splitlines()
                       if SOFT_DOUBLE.match(s.split()[-1])})
        if soft:
            failures.append(f"the {opt} Lie-Euler firmware links software double routines: {soft}")
        rows[opt] = map_sizes(mapfile, library_objects)
        size = run([tools["size"], str(elf)]).splitlines()[1].split()
        images[opt] = (int(size[0]), int(size[1]), int(size[2]))
        stacks[opt] = measure_stack(tools, elf)
    return rows, stacks, images, failures


# ---- the report --------------------------------------------------------------------------------
def report(tools, build):
    version = run([tools["cc"], "--version"]).splitlines()[0]
    lines_fn, union = per_function(tools, build)
    rows, stacks, images, failures = firmware(tools, build)
    step = union["-O2"][2]
    out = [f"Compiler `{version}`, `{' '.join(CPU_FLAGS)} -std=c99 -ffp-contract=off -DSR_USE_FLOAT` "
           "plus the level shown; generated by `make cross-report` (`tools/m4_report.py`).", "",
           "**Per function** (float build): flash in bytes, own code / with every library function "
           "it reaches (what `--gc-sections` keeps if only that function is called; libm not "
           "included); stack in bytes, own frame / worst case through its callees (libm counted 0). "
           "No function has static RAM: its RAM is its stack plus the caller's `sr_model` "
           "(170 floats and an int, 684 bytes) and arrays (a state is 35 floats, 140 bytes).", "", *lines_fn, ""]
    origins = ["library", "libm", "libgcc", "newlib + semihosting", "start-up + main"]
    out += ["**A Lie–Euler-only firmware** (`c/cross/lie_euler_firmware.c`: `sr_model_init`, "
            "`sr_check_state`, then `sr_accel` and a Lie–Euler step per tick; linked with "
            "`-ffunction-sections -fdata-sections -Wl,--gc-sections` for the mps2-an386 with newlib "
            "and semihosting), bytes of flash / static RAM by origin, from the linker map:", "",
            "| part | -O2 | -Os |", "|---|---:|---:|"]
    for name in origins:
        cells = [" / ".join(map(str, rows[opt].get(name, [0, 0]))) for opt in LEVELS]
        out.append(f"| {name} | {cells[0]} | {cells[1]} |")
    cells = [f"{images[opt][0] + images[opt][1]} / {images[opt][1] + images[opt][2]}" for opt in LEVELS]
    out += [f"| whole image (`size`: text + data / data + bss) | {cells[0]} | {cells[1]} |", ""]
    libm = {opt: rows[opt].get("libm", [0])[0] for opt in LEVELS}
    verdict = {opt: "met" if union[opt][0] + libm[opt] <= FLASH_TARGET else "missed" for opt in LEVELS}
    out += [f"**Target: `sr_accel` + a Lie–Euler step ≤ {FLASH_TARGET} bytes of flash.**  Library "
            f"code reachable from `sr_accel` and `{step[:-2]}` (SR_LIE_EULER), each function once: "
            f"{union['-O2'][0]} bytes at -O2, {union['-Os'][0]} at -Os"
            + (" (`sr_step` reaches every method)" if step == "sr_step_f" else "") + "; with "
            f"what libm adds to this image ({libm['-O2']} bytes: the float build's sine and cosine are the "
            "library's own, c/src/sr_trig.c, where newlib's `sinf` and `cosf` with their argument reduction "
            f"and its 2/π table took 4,349) {union['-O2'][0] + libm['-O2']} "
            f"and {union['-Os'][0] + libm['-Os']}: {verdict['-O2']} at -O2, {verdict['-Os']} at -Os.  "
            "The library built with `-DSR_PAPER_ONLY` (the paper-geometry kernels only, for a robot of "
            "the paper's geometry; docs/robots.md) reaches "
            f"{union['-O2'][3]} bytes at -O2 and {union['-Os'][3]} at -Os, with libm "
            f"{union['-O2'][3] + libm['-O2']} and {union['-Os'][3] + libm['-Os']}: "
            f"{'met' if union['-O2'][3] + libm['-O2'] <= FLASH_TARGET else 'missed'} at -O2, "
            f"{'met' if union['-Os'][3] + libm['-Os'] <= FLASH_TARGET else 'missed'} at -Os.  "
            "No software double routine (`__aeabi_d*`) is linked (checked).", ""]
    out += ["**Stack measured under QEMU** (mps2-an386; the free stack painted, one call made, the "
            "deepest changed word found; libm included, resolution 4 bytes, at least 64):", "",
            "| entry point | -O2 | -Os |", "|---|---:|---:|"]
    for name in stacks["-O2"]:
        out.append(f"| `{name}` | {stacks['-O2'][name]} | {stacks['-Os'].get(name, '-')} |")
    measured_step = min(s.get("sr_step_lie_euler", s.get("sr_step(SR_LIE_EULER)")) for s in stacks.values())
    static_step = min(union[opt][1] for opt in LEVELS)
    static_paper = min(union[opt][4] for opt in LEVELS)
    out += ["", f"**Target: stack of a Lie–Euler step ≤ {STACK_TARGET} bytes.**  Measured "
            f"{measured_step} bytes (best level, libm included): "
            f"{'met' if measured_step <= STACK_TARGET else 'missed'}; the static bound of "
            f"`{step[:-2]}` over its whole call graph is {static_step} bytes (best level): "
            f"{'met' if static_step <= STACK_TARGET else 'missed'}"
            + (" (`sr_step` dispatches to every method: the bound is that of CF4)" if step == "sr_step_f" else "")
            + f"; built with `-DSR_PAPER_ONLY` the bound is {static_paper} bytes: "
            f"{'met' if static_paper <= STACK_TARGET else 'missed'}."]
    return "\n".join(out) + "\n", failures


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build/cross/report", help="scratch directory")
    parser.add_argument("--cross-prefix", default="arm-none-eabi-")
    parser.add_argument("--qemu", default="qemu-system-arm")
    parser.add_argument("--update", metavar="MARKDOWN", help=f"replace the text between {BEGIN} and {END}")
    args = parser.parse_args(argv)
    p = args.cross_prefix
    tools = {"cc": p + "gcc", "nm": p + "nm", "size": p + "size", "qemu": args.qemu}
    build = pathlib.Path(args.build).resolve()
    text, failures = report(tools, build)
    sys.stdout.write(text)
    for f in failures:
        print(f"m4_report: FAIL: {f}")
    if args.update and not failures:
        path = pathlib.Path(args.update)
        doc = path.read_text()
        if BEGIN not in doc or END not in doc:
            sys.exit(f"m4_report: {path} has no {BEGIN} ... {END} block")
        head, rest = doc.split(BEGIN, 1)
        path.write_text(head + BEGIN + "\n" + text + END + rest.split(END, 1)[1])
        print(f"m4_report: updated {path}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
