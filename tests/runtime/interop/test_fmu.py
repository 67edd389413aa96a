"""The FMUs of `make fmu` (runtime/interop/fmu.py, fmu/): valid by FMPy, the same numbers as the
runtime, the parameters where their names say, errors that name what is wrong."""
import dataclasses
import shutil
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.simulation import instantiate_fmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from bindings._sr import lib  # noqa: E402
from runtime import Model, Params, initial_state  # noqa: E402
from runtime.control.geometry import heading  # noqa: E402
from runtime.interop import fmu  # noqa: E402
from runtime.params import FLAT_FIELDS, flat_names, SHAPES  # noqa: E402
from runtime.scenario import load_scenario, run_scenario  # noqa: E402
from runtime.verification.contact import ReferenceContact  # noqa: E402

VERSIONS = (2, 3)
STATE_NAMES = [v.name for v in fmu.variables() if v.kind == "SR_FMU_STATE"]


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """Both FMUs, built once (the library is compiled once for both)."""
    return fmu.build(VERSIONS, tmp_path_factory.mktemp("fmu"))


class Instance:
    """One co-simulation instance through FMPy's FMI 2 or FMI 3 API, its log kept."""

    def __init__(self, version, path, tmp_path):
        self.version = version
        description = fmpy.read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in description.modelVariables}
        self.messages = []
        if version == 2:
            self._log = lambda env, name, status, category, message: self.messages.append(message.decode())
        else:
            self._log = lambda env, status, category, message: self.messages.append(message.decode())
        self.fmu = instantiate_fmu(fmpy.extract(str(path), str(tmp_path / f"fmi{version}")), description,
                                   fmi_type="CoSimulation", logger=self._log)

    def set(self, **values):
        vrs, reals = [self.vr[name] for name in values], [float(v) for v in values.values()]
        (self.fmu.setReal if self.version == 2 else self.fmu.setFloat64)(vrs, reals)

    def set_method(self, code):
        if self.version == 2:
            self.fmu.setInteger([self.vr["method"]], [code])
        else:
            self.fmu.setInt64([self.vr["method"]], [code])

    def start(self):
        if self.version == 2:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.exitInitializationMode()

    def get(self, *names):
        vrs = [self.vr[name] for name in names]
        return np.array(self.fmu.getReal(vrs) if self.version == 2 else self.fmu.getFloat64(vrs))

    def step(self, t, h):
        self.fmu.doStep(t, h)


@pytest.mark.parametrize("version", VERSIONS)
def test_fmpy_validation_finds_no_problem(fmus, version):
    assert validate_fmu(str(fmus[version])) == []


@pytest.mark.parametrize("version", VERSIONS)
def test_every_general_parameter_is_a_fixed_parameter_with_a_unit_and_the_paper_robot_as_start(fmus, version):
    with zipfile.ZipFile(fmus[version]) as archive:
        root = ET.fromstring(archive.read("modelDescription.xml"))
    units = {u.get("name") for u in root.iter("Unit")}
    parameters = {}
    for element in root.find("ModelVariables"):
        if element.get("causality") == "parameter":
            typed = element if version == 3 else element[0]
            parameters[element.get("name")] = (element.get("variability"), typed.get("unit"), typed.get("start"))
    expected = Params().as_array()
    names = [n for field in SHAPES for n in flat_names(field, SHAPES[field])]
    assert len(names) == len(FLAT_FIELDS)
    for name in names:
        variability, unit, start = parameters[name]
        assert variability == "fixed"
        assert unit in units
        assert float(start) == expected[getattr(lib, f"SR_P_{name}")]


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("scenario", ["t-shape", "tilted-pendulum", "tilted-yoke"])
def test_simulating_the_fmu_equals_the_runtime_on_the_papers_runs(fmus, version, scenario):
    loaded = load_scenario(scenario)
    result = fmu.simulate_scenario(fmus[version], loaded)
    reference = run_scenario(loaded)
    states = np.column_stack([result[name] for name in STATE_NAMES])
    assert states.shape == reference.trajectory.shape
    assert np.max(np.abs(states - reference.trajectory)) <= 1e-12
    assert np.max(np.abs(result["energy"] - reference.energy)) <= 1e-12
    assert np.max(np.abs(np.angle(np.exp(1j * (result["heading"] - heading(reference.trajectory)))))) <= 1e-12


@pytest.mark.parametrize("version", VERSIONS)
def test_every_parameter_reaches_its_c_entry_a_general_robot_on_a_slope_with_rkmk4(fmus, version):
    # battery-geared: off-centre yoke mass, full tensors, rotors and gears; slope and yaw added
    # so that every parameter and initial condition is away from its default.
    loaded = load_scenario("battery-geared")
    loaded = dataclasses.replace(loaded, steps=600, params=dataclasses.replace(loaded.params, slope=0.01),
                                 x0=initial_state(theta_Y=0.2, theta_P=-0.1, q=(0.5, -0.25, loaded.params.r),
                                                  R_S=np.array([[0.8, -0.6, 0], [0.6, 0.8, 0], [0, 0, 1.0]]),
                                                  w_S=(0.1, -0.2, 0.05), w_Y=0.3, w_P=-0.2, r=loaded.params.r))
    assert loaded.method == "rkmk4"
    result = fmu.simulate_scenario(fmus[version], loaded)
    reference = run_scenario(loaded)
    states = np.column_stack([result[name] for name in STATE_NAMES])
    assert np.max(np.abs(states - reference.trajectory)) <= 1e-12


def test_at_rest_on_a_level_floor_the_floor_carries_the_weight_and_no_friction(fmus, tmp_path):
    instance = Instance(2, fmus[2], tmp_path)
    instance.start()
    params = Params()
    F_t_x, F_t_y, F_n = instance.get("F_t_x", "F_t_y", "F_n")
    assert F_n == pytest.approx((params.m_S + params.m_Y + params.m_P) * params.g, rel=1e-14)
    assert abs(F_t_x) <= 1e-12 and abs(F_t_y) <= 1e-12


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("scenario", ["t-shape", "battery-geared"])
def test_the_contact_force_is_the_independent_references_multiplier(fmus, version, scenario, tmp_path):
    loaded = load_scenario(scenario)
    torques = loaded.torque_at_step_starts(loaded.steps)
    params = dataclasses.replace(loaded.params, slope=0.05)
    trajectory = Model(params).simulate(loaded.x0, loaded.dt, 2000, torques[:2000], method=loaded.method)
    reference = ReferenceContact(params.as_dict())
    values = fmu.start_values(params, loaded.x0, loaded.method, loaded.dt)
    instance = Instance(version, fmus[version], tmp_path)
    instance.set(**{k: v for k, v in values.items() if k != "method"})
    instance.set_method(values["method"])
    instance.start()
    checked = 0
    for k in range(2000):
        instance.set(u_Y=torques[k, 0], u_P=torques[k, 1])
        if k % 250 == 0:
            expected = reference.force(trajectory[k], torques[k])
            assert instance.get("F_t_x", "F_t_y", "F_n") == pytest.approx(
                expected, rel=1e-9, abs=1e-9 * abs(expected[2]))
            checked += 1
        instance.step(k * loaded.dt, loaded.dt)
    assert checked == 8


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name, value, text", [
    ("m_S", -1.0, "m_S: must be > 0, got -1"),
    ("J_P_yy", 5.0, "J_P (J_P_xx .. J_P_yz): not a physical inertia tensor"),
    ("c_Y_z", 0.4, "c_Y (c_Y_x .. c_Y_z): "),
    ("slope", 2.0, "slope: "),
    ("internal_step", 0.0, "internal_step: must be > 0 and finite, got 0"),
    ("theta_P_0", float("inf"), "theta_P_0: must be finite, got inf"),
])
def test_a_bad_parameter_is_an_error_whose_message_names_it(fmus, version, name, value, text, tmp_path):
    instance = Instance(version, fmus[version], tmp_path)
    instance.set(**{name: value})
    with pytest.raises(fmpy.fmi1.FMICallException) as failure:
        instance.start()
    assert failure.value.status == 3          # fmi2Error / fmi3Error
    assert len(instance.messages) == 1 and instance.messages[0].startswith(text)


@pytest.mark.parametrize("version", VERSIONS)
def test_an_unknown_stepper_is_an_error_naming_the_method_parameter(fmus, version, tmp_path):
    instance = Instance(version, fmus[version], tmp_path)
    with pytest.raises(fmpy.fmi1.FMICallException):
        instance.set_method(7)
    assert instance.messages[0].startswith("method: not a stepper of this FMU (lie-euler, rkmk4, cf4")


@pytest.mark.parametrize("version", VERSIONS)
def test_a_failed_step_is_an_error_with_the_stepper_s_reason(fmus, version, tmp_path):
    instance = Instance(version, fmus[version], tmp_path)
    instance.start()
    instance.step(0.0, 0.01)
    instance.set(u_Y=1e308)
    with pytest.raises(fmpy.fmi1.FMICallException) as failure:
        instance.step(0.01, 0.01)
    assert failure.value.status == 3
    assert instance.messages == ["the step from t = 0.01 failed at t = 0.01: non-finite value"]


@pytest.mark.parametrize("version", VERSIONS)
def test_a_non_finite_input_is_an_error_naming_it(fmus, version, tmp_path):
    instance = Instance(version, fmus[version], tmp_path)
    instance.start()
    instance.set(u_P=float("nan"))
    with pytest.raises(fmpy.fmi1.FMICallException):
        instance.step(0.0, 0.01)
    assert instance.messages == ["u_P: must be finite, got nan"]


@pytest.mark.parametrize("version", VERSIONS)
def test_a_parameter_cannot_change_after_initialisation(fmus, version, tmp_path):
    instance = Instance(version, fmus[version], tmp_path)
    instance.start()
    with pytest.raises(fmpy.fmi1.FMICallException):
        instance.set(r=0.5)
    assert instance.messages == ["r: a parameter is set only before the end of initialisation"]


def test_a_communication_step_takes_equal_internal_steps_no_longer_than_the_internal_step(fmus, tmp_path):
    x0 = initial_state(theta_P=0.5)
    expected = Model(Params()).simulate(x0, 0.025, 4, method="lie-euler")[-1]
    instance = Instance(2, fmus[2], tmp_path)
    instance.set(theta_P_0=0.5, internal_step=0.03)
    instance.start()
    instance.step(0.0, 0.1)
    assert np.max(np.abs(instance.get(*STATE_NAMES) - expected)) <= 1e-14


def test_the_cli_reports_an_unsupported_fmi_version_without_a_traceback(capsys):
    from runtime.__main__ import main
    with pytest.raises(SystemExit) as exit_:
        main(["export", "fmu", "--fmi", "4"])
    assert exit_.value.code == 2
    assert "invalid choice: 4" in capsys.readouterr().err


def test_the_fmus_sources_build_a_binary_that_computes_the_same(fmus, tmp_path):
    """What a tool on another platform does (e.g. for Simulink on Windows): FMPy's CMake build of
    the FMU's sources/ (FMI 3: sources/buildDescription.xml) in place of the shipped binary."""
    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed")
    from fmpy.build import build_platform_binary
    unzipped = tmp_path / "unzipped"
    fmpy.extract(str(fmus[3]), str(unzipped))
    shutil.rmtree(unzipped / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(unzipped, build_dir=tmp_path / "build", configuration="Debug")   # -O0: quicker
    start = {"theta_P_0": 0.5, "method": 2}
    rebuilt = fmpy.simulate_fmu(str(unzipped), stop_time=1.0, output_interval=0.01, start_values=start)
    shipped = fmpy.simulate_fmu(str(fmus[3]), stop_time=1.0, output_interval=0.01, start_values=start)
    assert max(np.max(np.abs(rebuilt[n] - shipped[n])) for n in shipped.dtype.names) <= 1e-12


def writable_objects(obj):
    """The objects of a compiled file in writable sections: .data or .bss (not the relocated
    read-only .data.rel.ro of position-independent constants)."""
    import subprocess
    table = subprocess.run(["objdump", "-t", str(obj)], check=True, capture_output=True, text=True).stdout
    found = []
    for line in table.splitlines():
        fields = line.split()
        if len(fields) >= 5 and "O" in fields[1:-3]:
            section = fields[-3]
            if section in ("*COM*", ".bss", ".data") or section.startswith((".bss.", ".data.")) and \
                    not section.startswith(".data.rel.ro"):
                found.append(f"{section} {fields[-1]}")
    return found


@pytest.mark.parametrize("glue", ["sr_fmu.c", "fmi2.c", "fmi3.c"])
def test_the_glue_has_no_mutable_global(glue, tmp_path):
    """Instances share nothing: no object of the glue lands in a writable section."""
    if shutil.which("objdump") is None:
        pytest.skip("objdump is not installed")
    import subprocess
    (tmp_path / "sr_fmu_variables.h").write_text(fmu.variables_header())
    obj = tmp_path / "glue.o"
    subprocess.run([shutil.which("cc") or "gcc", *fmu.CFLAGS, *(f"-I{d}" for d in fmu.include_dirs(tmp_path)),
                    "-c", str(fmu.GLUE / glue), "-o", str(obj)], check=True)
    assert writable_objects(obj) == []


def test_the_scan_finds_a_mutable_global(tmp_path):
    import subprocess
    source = tmp_path / "globals.c"
    source.write_text("int counter;\nint seeded = 3;\nstatic int hidden;\nint *touch(void) { return &hidden; }\n"
                      "const char *const names[] = {\"a\"};\n")
    subprocess.run([shutil.which("cc") or "gcc", "-fPIC", "-fno-common", "-c", str(source), "-o",
                    str(tmp_path / "globals.o")], check=True)
    assert sorted(name.split()[-1] for name in writable_objects(tmp_path / "globals.o")) == [
        "counter", "hidden", "seeded"]
