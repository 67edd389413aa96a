#!/usr/bin/env python3
"""Code size and worst-case stack of every public function of the C library.

    python3 tools/size_report.py                      # print the Markdown tables
    python3 tools/size_report.py --update docs/embedding.md
    python3 tools/size_report.py --cc arm-none-eabi-gcc --cflags "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"

(also `make size-report` in c/).  Standard library only; needs GCC >= 10 and
binutils' nm.  A documentation tool: the library itself builds without Python.

Method.  Every library source (generated/*.c, c/src/*.c) is compiled at -Os and at
-O2, for double and for float, with

    -ffunction-sections -fstack-usage -fcallgraph-info=su

* Code size: the size of each function's own code, from `nm -S` (with
  -ffunction-sections every function is its own section, so the symbol size is
  its text).  "with callees" adds every library function it can reach in the
  call graph, each once: what a linker with --gc-sections keeps if only that
  function is used.  Read-only constants (.rodata) are not included.
* Stack: GCC's own frame size of every function (the .su/.ci "N bytes"; on
  x86-64 it includes the return address), and the worst case over the call
  graph that GCC writes with -fcallgraph-info: worst(f) = frame(f) +
  max over callees worst(callee).  The graph is the one after optimization
  (inlined helpers are part of their caller's frame).  Calls into libm
  (sin, cos, sincos, sqrt, pow, ...) are outside the library and counted as
  0; they are listed so that the libm's frames can be added for a target.
  There are no function pointers or recursion in the library; the script
  fails if it finds a cycle or a frame that GCC marks "dynamic" (not bounded).
"""
import argparse
import collections
import concurrent.futures
import os
import pathlib
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
C_DIR = ROOT / "c"
INCLUDE = C_DIR / "include"
HEADERS = (INCLUDE / "spherical_robot.h", INCLUDE / "sr_sensors.h", INCLUDE / "sr_ekf.h")
BEGIN, END = "<!-- size-report:begin -->", "<!-- size-report:end -->"

Node = collections.namedtuple("Node", "title symbol obj frame qualifier")


def public_functions():
    """Names of the functions declared in the public headers (HEADERS), in order."""
    text = "".join(re.sub(r"/\*.*?\*/", "", header.read_text(), flags=re.S) for header in HEADERS)
    return re.findall(r"^[A-Za-z_][\w \t\*]*?\b(sr_\w+)\s*\(", text, flags=re.M)


def sources():
    return sorted((ROOT / "generated").glob("*.c")) + sorted((C_DIR / "src").glob("*.c"))


def compile_variant(cc, cflags, opt, use_float, out_dir):
    """Compile every source, one compiler per core; return the object paths (the .su/.ci files sit
    next to them)."""
    def compile_one(src):
        obj = out_dir / (src.stem + ".o")
        cmd = [cc, "-std=c99", opt, "-ffp-contract=off", "-ffunction-sections", "-fstack-usage",
               "-fcallgraph-info=su", f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", *cflags, "-c", str(src),
               "-o", str(obj)]
        if use_float:
            cmd.insert(1, "-DSR_USE_FLOAT")
        subprocess.run(cmd, check=True, cwd=out_dir)
        return obj
    with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 1) as pool:
        return list(pool.map(compile_one, sources()))


def symbol_sizes(nm, obj):
    """{symbol: size in bytes} of the functions defined in obj."""
    out = subprocess.run([nm, "-S", "--defined-only", str(obj)], check=True, capture_output=True,
                         text=True).stdout
    sizes = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "Tt":
            sizes[parts[3]] = int(parts[1], 16)
    return sizes


def read_callgraph(ci_path, obj):
    """Nodes defined in one .ci file and its edges (titles)."""
    nodes, edges = {}, []
    node_re = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
    edge_re = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
    for line in ci_path.read_text().splitlines():
        m = node_re.match(line)
        if m:
            title, label = m.groups()
            frame = re.search(r"\\n(\d+) bytes \(([^)]*)\)", label)
            if frame:  # defined here (external declarations carry no frame)
                symbol = title.split(":", 1)[1] if ":" in title else title
                nodes[title] = Node(title, symbol, obj, int(frame.group(1)), frame.group(2))
            continue
        m = edge_re.match(line)
        if m:
            edges.append(m.groups())
    return nodes, edges


class Library:
    """The call graph, frames and sizes of one compiled variant of the library."""

    def __init__(self, objs, nm):
        self.nodes, self.calls = {}, collections.defaultdict(set)
        self.sizes = {}
        for obj in objs:
            nodes, edges = read_callgraph(obj.with_suffix(".ci"), obj)
            self.nodes.update(nodes)
            for src, dst in edges:
                self.calls[src].add(dst)
            for sym, size in symbol_sizes(nm, obj).items():
                self.sizes[(obj, sym)] = size
        for node in self.nodes.values():
            if "dynamic" in node.qualifier and "bounded" not in node.qualifier:
                sys.exit(f"size_report: unbounded dynamic stack in {node.title}")

    def size(self, title):
        node = self.nodes[title]
        return self.sizes.get((node.obj, node.symbol), 0)

    def reachable(self, title):
        """Library functions reachable from title (itself included) and the external callees."""
        seen, external, todo = set(), set(), [title]
        while todo:
            t = todo.pop()
            if t in seen:
                continue
            if t not in self.nodes:
                external.add(t)
                continue
            seen.add(t)
            todo.extend(self.calls[t])
        return seen, external

    def worst_stack(self, title, path=()):
        if title in path:
            sys.exit(f"size_report: recursion through {title}")
        if title not in self.nodes:
            return 0
        below = [self.worst_stack(c, path + (title,)) for c in self.calls[title]]
        return self.nodes[title].frame + max(below, default=0)

    def row(self, title):
        seen, external = self.reachable(title)
        return {
            "own": self.size(title),
            "total": sum(self.size(t) for t in seen),
            "frame": self.nodes[title].frame,
            "worst": self.worst_stack(title),
            "external": sorted(external),
        }


def berkeley_totals(size_tool, objs):
    """(text incl. read-only data, data, bss) summed over objs, from `size`."""
    out = subprocess.run([size_tool, *map(str, objs)], check=True, capture_output=True, text=True).stdout
    totals = [0, 0, 0]
    for line in out.splitlines()[1:]:
        for i, v in enumerate(line.split()[:3]):
            totals[i] += int(v)
    return totals


def report(cc, cflags, nm, size_tool):
    publics = public_functions()
    rows, internals, totals = {}, {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for scalar in ("double", "float"):
            for opt in ("-O2", "-Os"):
                out_dir = pathlib.Path(tmp) / f"{scalar}{opt}"
                out_dir.mkdir()
                objs = compile_variant(cc, cflags, opt, scalar == "float", out_dir)
                lib = Library(objs, nm)
                totals[(scalar, opt)] = berkeley_totals(size_tool, objs)
                suffix = "_f" if scalar == "float" else ""   # the float build's symbols carry _f
                for fn in publics:
                    if fn + suffix in lib.nodes:
                        rows[(scalar, opt, fn)] = lib.row(fn + suffix)
                # Global functions outside the public API: the generated kernels, internal steppers.
                for title in lib.nodes:
                    name = title[:-len(suffix)] if suffix and title.endswith(suffix) else title
                    if ":" not in title and name not in publics:
                        internals[name] = True
                        rows[(scalar, opt, name)] = lib.row(title)
    version = subprocess.run([cc, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    lines = [
        f"Compiler: `{version}`, flags `{' '.join(['-std=c99', '-ffp-contract=off', *cflags])}` "
        "plus the level shown.",
        "Text in bytes (own code / with every library function it reaches); stack in bytes "
        "(own frame / worst case through its callees, libm excluded).",
        "",
    ]
    for scalar in ("double", "float"):
        lines += [f"**sr_real = {scalar}**", "",
                  "| function | text -O2 | text -Os | stack -O2 | stack -Os | libm calls |",
                  "|---|---:|---:|---:|---:|---|"]
        for fn in publics + ["*internal*"] + sorted(internals):
            if fn == "*internal*":
                lines.append("| *internal, called by the above:* | | | | | |")
                continue
            o2, os_ = rows.get((scalar, "-O2", fn)), rows.get((scalar, "-Os", fn))
            if o2 is None or os_ is None:
                continue
            ext = sorted(set(o2["external"]) | set(os_["external"]))
            lines.append(f"| `{fn}` | {o2['own']} / {o2['total']} | {os_['own']} / {os_['total']} "
                         f"| {o2['frame']} / {o2['worst']} | {os_['frame']} / {os_['worst']} "
                         f"| {', '.join(ext) or '-'} |")
        lines.append("")
    lines += ["Whole library (`size`, text including read-only data / data / bss, bytes):", "",
              "| sr_real | -O2 | -Os |", "|---|---|---|"]
    for scalar in ("double", "float"):
        cells = [" / ".join(map(str, totals[(scalar, opt)])) for opt in ("-O2", "-Os")]
        lines.append(f"| {scalar} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines).rstrip() + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cc", default=os.environ.get("CC", "gcc"), help="C compiler (GCC >= 10)")
    parser.add_argument("--nm", default="nm", help="nm of the same toolchain")
    parser.add_argument("--size", default="size", help="size of the same toolchain")
    parser.add_argument("--cflags", default="", help="extra flags, e.g. the target CPU")
    parser.add_argument("--update", metavar="MARKDOWN",
                        help=f"replace the text between {BEGIN} and {END} in this file")
    args = parser.parse_args(argv)
    text = report(args.cc, shlex.split(args.cflags), args.nm, args.size)
    if not args.update:
        sys.stdout.write(text)
        return 0
    path = pathlib.Path(args.update)
    doc = path.read_text()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"size_report: {path} has no {BEGIN} ... {END} block")
    head, rest = doc.split(BEGIN, 1)
    path.write_text(head + BEGIN + "\n" + text + END + rest.split(END, 1)[1])
    print(f"size_report: updated {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
