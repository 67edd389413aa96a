"""The robot as a Functional Mock-up Unit: FMI 2.0 and FMI 3.0 co-simulation (docs/interop.md).

`python -m runtime export fmu [--out DIR] [--fmi 2] [--fmi 3]` (`make fmu`) writes
DIR/SphericalRobot.fmu (FMI 2.0) and DIR/fmi3/SphericalRobot.fmu (FMI 3.0): the C library and
the glue of fmu/ compiled for this platform, and a modelDescription.xml.

One table, `variables()`, decides every variable of the FMU: its value reference, name, causality,
unit and what it maps to in C.  It is built from the library's own tables: the parameters
(derive/parameters.py PARAMETERS, their units PARAMETER_MEANINGS, their defaults from `Params()`),
the state layout (derive/state.py STATE_BLOCKS, INPUT_NAMES, whose offsets the compiled module
reports as SR_X_*, SR_U_*) and the steppers (`runtime.model.METHODS`).  From it come both the
model description and the C header fmu/ reads (sr_fmu_variables.h, written into the build
folder), so the two cannot disagree.  The FMI headers are the standard's, shipped with FMPy.
"""
import argparse
import dataclasses
import hashlib
import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import uuid
import xml.etree.ElementTree as ET
import zipfile

import numpy as np

from bindings._sr import lib

ROOT = pathlib.Path(__file__).resolve().parents[2]
#: The C library the FMU is built from: every source of these folders (globs, relative to ROOT),
#: and the folders its headers are in.  The one place that knows where the library lives.
LIBRARY_SOURCES = ("generated/*.c", "c/src/*.c")
LIBRARY_INCLUDES = ("generated", "c/include", "c/src")
#: The FMU glue (fmu/): sr_fmu.c for both versions, fmi2.c or fmi3.c for one.
GLUE = ROOT / "fmu"
MODEL_IDENTIFIER = "SphericalRobot"
#: The flags of the library's own Makefile (c/Makefile), so that the FMU computes the same bits.
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-ffp-contract=off", "-fPIC",
          "-fvisibility=hidden")

#: The initial conditions, settable until initialisation ends: (name, unit, description).
INITIAL_CONDITIONS = (
    ("theta_Y_0", "rad", "initial yoke angle: R_Y = rot_x(theta_Y_0)"),
    ("theta_P_0", "rad", "initial pendulum angle: R_P = rot_y(theta_P_0)"),
    ("yaw_S_0", "rad", "initial shell attitude: R_S = rot_z(yaw_S_0)"),
    ("q_x_0", "m", "initial shell centre, x (q_z = r)"),
    ("q_y_0", "m", "initial shell centre, y"),
    ("w_S_x_0", "rad/s", "initial shell angular velocity, shell frame, x"),
    ("w_S_y_0", "rad/s", "initial shell angular velocity, shell frame, y"),
    ("w_S_z_0", "rad/s", "initial shell angular velocity, shell frame, z"),
    ("w_Y_0", "rad/s", "initial yoke speed"),
    ("w_P_0", "rad/s", "initial pendulum speed"),
)
#: The default stepper and internal step (the shipped scenarios').
DEFAULT_METHOD = "lie-euler"
DEFAULT_STEP = 0.01

#: Every unit the variables use, in SI base units (FMI's BaseUnit exponents).
UNITS = {
    "1": {}, "s": {"s": 1}, "m": {"m": 1}, "kg": {"kg": 1}, "rad": {"rad": 1},
    "kg.m2": {"kg": 1, "m": 2}, "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1},
    "m/s2": {"m": 1, "s": -2}, "rad/s": {"rad": 1, "s": -1}, "N.m": {"kg": 1, "m": 2, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2}, "N": {"kg": 1, "m": 1, "s": -2},
}


@dataclasses.dataclass(frozen=True)
class Variable:
    """One scalar variable of the FMU; its value reference is its position in `variables()`."""
    name: str
    kind: str               # the SR_FMU_* kind of fmu/sr_fmu.h
    index: str              # a C expression: the entry of the kind's array (e.g. SR_P_r, SR_X_q + 1)
    causality: str          # independent, input, parameter, output
    variability: str        # continuous or fixed
    unit: str
    description: str
    start: object = None    # float, or the method's code; None for calculated variables
    enumeration: bool = False


def _derive():
    """derive's parameters and state modules (SymPy: the dev extra, as `make fmu` installs it)."""
    try:
        from derive import parameters, state
    except ImportError as exc:
        raise ValueError(f"the FMU's tables come from derive/, which needs the dev extra "
                         f"(pip install -e '.[dev]'): {exc}") from None
    return parameters, state


def _state_names(block, length):
    if length == 9:
        return [f"{block}_{i + 1}{j + 1}" for i in range(3) for j in range(3)]
    if length == 3:
        return [f"{block}_{a}" for a in "xyz"]
    return [block]


def variables():
    """Every variable of the FMU, in value-reference order (time first)."""
    from runtime.model import METHODS
    from runtime.params import Params

    derive_parameters, derive_state = _derive()
    out = [Variable("time", "SR_FMU_TIME", "0", "independent", "continuous", "s", "simulation time")]
    for name, _ in sorted(derive_state.INPUT_NAMES, key=lambda item: getattr(lib, f"SR_U_{item[0]}")):
        unit, text = derive_state.INPUT_MEANINGS[name]
        out.append(Variable(name, "SR_FMU_INPUT", f"SR_U_{name}", "input", "continuous", unit,
                            f"{text}, held over each communication step", start=0.0))
    defaults = Params().as_array()
    for symbol in derive_parameters.PARAMETERS:
        name = str(symbol)
        unit, text = derive_parameters.meaning(name)
        out.append(Variable(name, "SR_FMU_PARAM", f"SR_P_{name}", "parameter", "fixed", unit, text,
                            start=float(defaults[getattr(lib, f"SR_P_{name}")])))
    for name, unit, text in INITIAL_CONDITIONS:
        out.append(Variable(name, "SR_FMU_INIT", f"SR_FMU_INIT_{name}", "parameter", "fixed", unit, text,
                            start=0.0))
    out.append(Variable("method", "SR_FMU_METHOD", "0", "parameter", "fixed", "",
                        "the stepper: " + ", ".join(METHODS), start=METHODS[DEFAULT_METHOD], enumeration=True))
    out.append(Variable("internal_step", "SR_FMU_STEP", "0", "parameter", "fixed", "s",
                        "the stepper's step: a communication step h takes ceil(h / internal_step) equal steps",
                        start=DEFAULT_STEP))
    for block, offset, length in sorted(derive_state.STATE_BLOCKS, key=lambda b: getattr(lib, f"SR_X_{b[0]}")):
        unit, text = derive_state.STATE_MEANINGS[block]
        for k, name in enumerate(_state_names(block, length)):
            out.append(Variable(name, "SR_FMU_STATE", f"SR_X_{block} + {k}", "output", "continuous", unit,
                                text if length == 1 else f"{text}: {name}"))
    out.append(Variable("heading", "SR_FMU_HEADING", "0", "output", "continuous", "rad",
                        "direction of forward rolling from the plane's x axis, atan2(a_x, -a_y), a = R_S e_x"))
    out.append(Variable("energy", "SR_FMU_ENERGY", "0", "output", "continuous", "J",
                        "total energy: kinetic + gravitational potential"))
    for k, (name, text) in enumerate((("F_t_x", "contact force of the floor on the shell, tangential, x"),
                                      ("F_t_y", "contact force of the floor on the shell, tangential, y"),
                                      ("F_n", "contact force of the floor on the shell, normal"))):
        out.append(Variable(name, "SR_FMU_CONTACT", str(k), "output", "continuous", "N",
                            f"{text} (plane frame; from the total momentum balance at the present input)"))
    return out


def _number(value):
    return repr(float(value))


def token(table=None):
    """The GUID / instantiation token: a hash of the variable table and the FMU glue's interface,
    so that an XML and a binary of different tables refuse each other."""
    table = variables() if table is None else table
    digest = hashlib.sha256(repr(table).encode() + (GLUE / "sr_fmu.h").read_bytes()).hexdigest()
    return "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, f"spherical-robot-fmu:{digest}")) + "}"


def variables_header(table=None):
    """sr_fmu_variables.h: the table as C, for fmu/sr_fmu.h."""
    from runtime.model import METHODS

    table = variables() if table is None else table
    by_kind = {}
    for v in table:
        by_kind.setdefault(v.kind, []).append(v)
    lines = ["/* Written by runtime/interop/fmu.py from the FMU's variable table; do not edit. */",
             "#ifndef SR_FMU_VARIABLES_H", "#define SR_FMU_VARIABLES_H", "",
             f'#define SR_FMU_TOKEN "{token(table)}"', f"#define SR_FMU_NVARS {len(table)}",
             f"#define SR_FMU_NINIT {len(INITIAL_CONDITIONS)}"]
    lines += [f"#define SR_FMU_INIT_{name} {i}" for i, (name, _, _) in enumerate(INITIAL_CONDITIONS)]
    lines.append("/* By value reference. */")
    lines.append("#define SR_FMU_VARIABLES { \\")
    lines += [f"    {{{v.kind}, {v.index}}}, /* {vr}: {v.name} */ \\" for vr, v in enumerate(table)]
    lines.append("}")
    lines.append("#define SR_FMU_NAMES { \\")
    lines += [f'    "{v.name}", \\' for v in table]
    lines.append("}")
    lines.append("#define SR_FMU_PARAM_START { \\")
    lines += [f"    [{v.index}] = {_number(v.start)}, \\" for v in by_kind["SR_FMU_PARAM"]]
    lines.append("}")
    lines.append("#define SR_FMU_INIT_START { \\")
    lines += [f"    [{v.index}] = {_number(v.start)}, \\" for v in by_kind["SR_FMU_INIT"]]
    lines.append("}")
    lines.append(f"#define SR_FMU_METHOD_START {by_kind['SR_FMU_METHOD'][0].start}")
    lines.append(f"#define SR_FMU_STEP_START {_number(by_kind['SR_FMU_STEP'][0].start)}")
    lines.append("#define SR_FMU_METHODS {" + ", ".join(str(code) for code in METHODS.values()) + "}")
    lines.append(f'#define SR_FMU_METHOD_NAMES "{", ".join(METHODS)}"')
    lines += ["", "#endif", ""]
    return "\n".join(lines)


def _units_used(table):
    used = sorted({v.unit for v in table if v.unit})
    unknown = [u for u in used if u not in UNITS]
    if unknown:
        raise ValueError(f"units {unknown}: not in UNITS (runtime/interop/fmu.py)")
    return used


def _unit_definitions(parent, table):
    units = ET.SubElement(parent, "UnitDefinitions")
    for name in _units_used(table):
        unit = ET.SubElement(units, "Unit", name=name)
        if UNITS[name]:
            ET.SubElement(unit, "BaseUnit", {k: str(e) for k, e in UNITS[name].items()})


def _method_items():
    from runtime.model import METHODS
    return [{"name": name, "value": str(code)} for name, code in METHODS.items()]


def model_description(version, table=None, sources=()):
    """modelDescription.xml (text) of the FMI `version` (2 or 3); `sources`: the names of the C
    files under sources/ that build the binary (FMI 2 lists them here, FMI 3 in
    sources/buildDescription.xml)."""
    if version not in (2, 3):
        raise ValueError(f"version: FMI 2 or 3, got {version!r}")
    table = variables() if table is None else table
    common = {"modelName": MODEL_IDENTIFIER,
              "description": "Fiori's yoke-pendulum spherical robot rolling without slipping on a plane "
                             "(Lie-group model; verified C kernels)",
              "generationTool": "spherical-robot-kernels (python -m runtime export fmu)",
              "variableNamingConvention": "flat"}
    if version == 2:
        root = ET.Element("fmiModelDescription", fmiVersion="2.0", guid=token(table), numberOfEventIndicators="0",
                          **common)
        cosimulation = ET.SubElement(root, "CoSimulation", modelIdentifier=MODEL_IDENTIFIER,
                                     canHandleVariableCommunicationStepSize="true", canGetAndSetFMUstate="false",
                                     canSerializeFMUstate="false", canNotUseMemoryManagementFunctions="false")
        if sources:
            files = ET.SubElement(cosimulation, "SourceFiles")
            for name in sources:
                ET.SubElement(files, "File", name=name)
    else:
        root = ET.Element("fmiModelDescription", fmiVersion="3.0", instantiationToken=token(table), **common)
        ET.SubElement(root, "CoSimulation", modelIdentifier=MODEL_IDENTIFIER,
                      canHandleVariableCommunicationStepSize="true", canGetAndSetFMUState="false",
                      canSerializeFMUState="false", hasEventMode="false", providesIntermediateUpdate="false",
                      canReturnEarlyAfterIntermediateUpdate="false")
    _unit_definitions(root, table)
    types = ET.SubElement(root, "TypeDefinitions")
    if version == 2:
        enumeration = ET.SubElement(ET.SubElement(types, "SimpleType", name="Method"), "Enumeration")
    else:
        enumeration = ET.SubElement(types, "EnumerationType", name="Method")
    for item in _method_items():
        ET.SubElement(enumeration, "Item", item)
    categories = ET.SubElement(root, "LogCategories")
    ET.SubElement(categories, "Category", name="logStatusError", description="errors, with their reason")
    ET.SubElement(root, "DefaultExperiment", startTime="0", stopTime="10", stepSize=_number(DEFAULT_STEP))
    variables_element = ET.SubElement(root, "ModelVariables")
    for vr, v in enumerate(table):
        attributes = {"name": v.name, "valueReference": str(vr), "description": v.description,
                      "causality": v.causality, "variability": v.variability}
        if v.causality == "parameter":
            attributes["initial"] = "exact"
        type_attributes = {}
        if v.unit:
            type_attributes["unit"] = v.unit
        if v.start is not None:
            type_attributes["start"] = str(v.start) if v.enumeration else _number(v.start)
        if v.enumeration:
            type_attributes["declaredType"] = "Method"
            type_attributes.pop("unit", None)
        if version == 2:
            element = ET.SubElement(variables_element, "ScalarVariable", attributes)
            ET.SubElement(element, "Enumeration" if v.enumeration else "Real", type_attributes)
        else:
            ET.SubElement(variables_element, "Enumeration" if v.enumeration else "Float64",
                          {**attributes, **type_attributes})
    structure = ET.SubElement(root, "ModelStructure")
    outputs = [vr for vr, v in enumerate(table) if v.causality == "output"]
    if version == 2:
        # index: 1-based position in ModelVariables; no dependencies attribute: on everything.
        out_element = ET.SubElement(structure, "Outputs")
        for vr in outputs:
            ET.SubElement(out_element, "Unknown", index=str(vr + 1))
        initial = ET.SubElement(structure, "InitialUnknowns")
        for vr in outputs:
            ET.SubElement(initial, "Unknown", index=str(vr + 1))
    else:
        for vr in outputs:
            ET.SubElement(structure, "Output", valueReference=str(vr))
        for vr in outputs:
            ET.SubElement(structure, "InitialUnknown", valueReference=str(vr))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def build_description(sources):
    """sources/buildDescription.xml of the FMI 3 FMU: one C99 file set."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    files = ET.SubElement(ET.SubElement(root, "BuildConfiguration", modelIdentifier=MODEL_IDENTIFIER),
                          "SourceFileSet", language="C99")
    for name in sources:
        ET.SubElement(files, "SourceFile", name=name)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def source_files(version, build_dir):
    """(C sources, headers) of the FMI `version` binary, as paths; every base name once (the FMU's
    sources/ folder is flat)."""
    sources = [*library_sources(), GLUE / "sr_fmu.c", GLUE / f"fmi{version}.c"]
    headers = sorted(p for d in LIBRARY_INCLUDES for p in (ROOT / d).glob("*.h"))
    headers += [GLUE / "sr_fmu.h", pathlib.Path(build_dir) / "sr_fmu_variables.h"]
    names = [p.name for p in sources + headers]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"sources: the base names {repeated} occur twice; the FMU's sources/ folder is flat")
    return sources, headers


def platform_folder(version):
    """The binaries/ folder of this platform in an FMU of FMI `version`."""
    system, machine = platform.system(), platform.machine().lower()
    arch = {"x86_64": "x86_64", "amd64": "x86_64", "aarch64": "aarch64", "arm64": "aarch64"}.get(machine)
    os_name = {"Linux": "linux", "Darwin": "darwin"}.get(system)
    if arch is None or os_name is None:
        raise ValueError(f"platform: building the FMU on {system} {machine} is not supported "
                         f"(Linux or macOS on x86-64 or ARM64)")
    if version == 2 and arch == "x86_64":
        return f"{os_name}64"
    return f"{arch}-{os_name}"


def fmi_headers():
    """The folder of the FMI 2 and 3 C headers that ship with FMPy."""
    try:
        import fmpy
    except ImportError:
        raise ValueError("fmpy: not installed; it brings the FMI headers (pip install -e '.[dev]')") from None
    folder = pathlib.Path(fmpy.__file__).parent / "c-code"
    if not (folder / "fmi2Functions.h").is_file() or not (folder / "fmi3Functions.h").is_file():
        raise ValueError(f"fmpy: no FMI 2 and 3 headers under {folder} (install fmpy from PyPI)")
    return folder


def library_sources():
    """The C library's sources, sorted (LIBRARY_SOURCES)."""
    sources = sorted(p for pattern in LIBRARY_SOURCES for p in ROOT.glob(pattern))
    if not sources:
        raise ValueError(f"no C sources matching {LIBRARY_SOURCES} under {ROOT}")
    return sources


def _run(command, what):
    result = subprocess.run([str(c) for c in command], capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{what} failed:\n{' '.join(map(str, command))}\n{result.stderr}")


def _compile(cc, source, obj, includes):
    _run([cc, *CFLAGS, *(f"-I{d}" for d in includes), "-c", source, "-o", obj], f"compiling {source}")


def include_dirs(build_dir):
    """The include folders of the build: build_dir (the variable header), the FMI headers, the glue
    and the library."""
    return [pathlib.Path(build_dir), fmi_headers(), GLUE, *(ROOT / d for d in LIBRARY_INCLUDES)]


def build(versions, out_dir, cc=None):
    """Writes the FMUs of the FMI `versions` (2, 3) under out_dir (`fmu_paths`); returns their paths.
    The library is compiled once for all of them."""
    cc = cc or os.environ.get("CC", "cc")
    paths = fmu_paths(out_dir)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "sr_fmu_variables.h").write_text(variables_header())
        includes = include_dirs(tmp)
        objects = []
        for k, source in enumerate([*library_sources(), GLUE / "sr_fmu.c"]):
            objects.append(tmp / f"{k}_{source.stem}.o")
            _compile(cc, source, objects[-1], includes)
        suffix = ".dylib" if platform.system() == "Darwin" else ".so"
        for version in versions:
            glue = tmp / f"fmi{version}.o"
            _compile(cc, GLUE / f"fmi{version}.c", glue, includes)
            binary = tmp / str(version) / f"{MODEL_IDENTIFIER}{suffix}"
            binary.parent.mkdir()
            _run([cc, "-shared", *objects, glue, "-lm", "-o", binary], f"linking the FMI {version} binary")
            out_path = paths[version]
            out_path.parent.mkdir(parents=True, exist_ok=True)
            partial = out_path.with_name(out_path.name + ".partial")
            sources, headers = source_files(version, tmp)
            names = [p.name for p in sources]
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as fmu:
                fmu.writestr("modelDescription.xml", model_description(version, sources=names))
                fmu.write(binary, f"binaries/{platform_folder(version)}/{binary.name}")
                # The sources, so that a tool on another platform (Windows for Simulink) can build
                # its own binary, e.g. with FMPy's build_platform_binary.
                for path in sources + headers:
                    fmu.write(path, f"sources/{path.name}")
                if version == 3:
                    fmu.writestr("sources/buildDescription.xml", build_description(names))
            os.replace(partial, out_path)
    return {v: paths[v] for v in versions}


def fmu_paths(out_dir):
    """{version: path} of the FMUs under out_dir."""
    out_dir = pathlib.Path(out_dir)
    return {2: out_dir / f"{MODEL_IDENTIFIER}.fmu", 3: out_dir / "fmi3" / f"{MODEL_IDENTIFIER}.fmu"}


def start_values(params, x0, method, step):
    """The FMU's parameters for a robot `params` (Params) starting at x0, as {name: value}: every
    general parameter, the initial conditions and the stepper.  ValueError when x0's R_S is not a
    rotation about the vertical (the FMU starts from R_S = rot_z(yaw_S_0))."""
    from runtime.model import METHODS
    from runtime.state import IDX_Q, IDX_RS, IDX_WP, IDX_WS, IDX_WY, pendulum_angle, yoke_angle

    x0 = np.asarray(x0, dtype=float)
    R_S = x0[IDX_RS].reshape(3, 3)
    yaw = float(np.arctan2(R_S[1, 0], R_S[0, 0]))
    c, s = np.cos(yaw), np.sin(yaw)
    if not np.allclose(R_S, [[c, -s, 0], [s, c, 0], [0, 0, 1]], rtol=0, atol=1e-12):
        raise ValueError(f"x0: R_S = {R_S.tolist()} is not a rotation about the vertical; the FMU starts "
                         f"from R_S = rot_z(yaw_S_0)")
    names = [v.name for v in variables() if v.kind == "SR_FMU_PARAM"]
    array = params.as_array()
    values = {name: float(array[getattr(lib, f"SR_P_{name}")]) for name in names}
    values.update({"theta_Y_0": float(yoke_angle(x0)), "theta_P_0": float(pendulum_angle(x0)), "yaw_S_0": yaw,
                   "q_x_0": float(x0[IDX_Q][0]), "q_y_0": float(x0[IDX_Q][1]),
                   "w_S_x_0": float(x0[IDX_WS][0]), "w_S_y_0": float(x0[IDX_WS][1]),
                   "w_S_z_0": float(x0[IDX_WS][2]), "w_Y_0": float(x0[IDX_WY]), "w_P_0": float(x0[IDX_WP]),
                   "method": METHODS[method], "internal_step": float(step)})
    return values


def torque_signal(torques, dt):
    """FMPy's input of piecewise-constant torques (steps, 2), row k held on [k dt, (k+1) dt): a
    structured array with a time column, each change a repeated time (FMPy takes the value after
    it), so every step sees its row exactly."""
    torques = np.asarray(torques, dtype=float)
    rows = [(0.0, *torques[0])]
    for k in range(1, len(torques)):
        if not np.array_equal(torques[k], torques[k - 1]):
            rows += [(k * dt, *torques[k - 1]), (k * dt, *torques[k])]
    rows.append((len(torques) * dt, *torques[-1]))
    return np.array(rows, dtype=[("time", np.float64), ("u_Y", np.float64), ("u_P", np.float64)])


def simulate_scenario(fmu_path, scenario, outputs=None):
    """Runs a scenario (runtime.scenario.Scenario) in the FMU with FMPy, one communication
    step per scenario step: FMPy's result (a structured array: time and the outputs)."""
    import fmpy

    torques = scenario.torque_at_step_starts(scenario.steps)
    return fmpy.simulate_fmu(str(fmu_path), start_time=0.0, stop_time=scenario.steps * scenario.dt,
                             output_interval=scenario.dt,
                             start_values=start_values(scenario.params, scenario.x0, scenario.method, scenario.dt),
                             input=torque_signal(torques, scenario.dt), output=outputs)


def main(argv):
    """`python -m runtime export fmu`: build the FMI 2.0 and 3.0 FMUs into --out."""
    parser = argparse.ArgumentParser(prog="python -m runtime export fmu",
                                     description="Build the robot as FMI 2.0 and FMI 3.0 co-simulation FMUs.")
    parser.add_argument("--out", default="out/fmu",
                        help="output folder: OUT/SphericalRobot.fmu (FMI 2), OUT/fmi3/SphericalRobot.fmu (FMI 3)")
    parser.add_argument("--fmi", type=int, choices=(2, 3), action="append",
                        help="the FMI version to build (repeatable; default both)")
    parser.add_argument("--cc", default=None, help="the C compiler (default: $CC or cc)")
    args = parser.parse_args(argv)
    try:
        for version, path in build(sorted(set(args.fmi or (2, 3))), args.out, args.cc).items():
            print(f"FMI {version}.0: {path}")
    except (ValueError, RuntimeError) as exc:
        print(f"export fmu: {exc}", file=sys.stderr)
        return 1
    return 0

