# Every target sets up what it needs: a virtual environment in .venv with the
# package installed in editable mode (which compiles the C kernels via cffi).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
C_SOURCES := $(wildcard generated/*.c generated/*.h c/include/*.h c/src/*.c c/src/*.h)

.PHONY: install test run generate verify bench sweep-bench figures soak fuzz c-lib c-test clean control envelope docs fmu estimation-figures consistency

$(STAMP): pyproject.toml setup.py bindings/build_sr.py bindings/fastcall.c $(C_SOURCES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $@

install: $(STAMP)

# One pytest worker per core; work-stealing keeps both busy while the long C builds run.
test: $(STAMP)
	$(PY) -m pytest -q -n auto --dist worksteal

run: $(STAMP)
	$(PY) -m runtime run all --out out --force

# The SymPy-emitted kernels (byte-reproducible), the extension rebuilt on them, then the firmware
# examples' designs (generated/lqr_task.h and nmpc_task.h: designs through LAPACK, whose last bits vary
# with the CPU; tests/runtime/control/test_firmware.py and test_nmpc_c.py hold them to fresh designs within 1e-7).
# derive/ needs only SymPy and CasADi (the `derive` extra), not the compiled extension, so it runs
# before the package is rebuilt: a C change that needs a newly emitted symbol then builds.
DERIVE_DEPS = $(shell $(PYTHON) -c "import tomllib; print(' '.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['derive']))")
generate:
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet $(DERIVE_DEPS)
	$(PY) -m derive
	$(MAKE) install
	$(PY) -m runtime firmware-table --out generated/lqr_task.h
	$(PY) -m runtime firmware-table --ekf-vector c/examples/ekf_lqr_vector
	$(PY) -m runtime firmware-table --slope-vector c/examples/slope_vector
	$(PY) -m runtime nmpc-c --header generated/nmpc_task.h --horizon 20 --node-periods 3

verify: $(STAMP)
	$(PY) -m runtime verify

bench: $(STAMP)
	$(PY) -m runtime bench --native
	$(PY) -m runtime nmpc-c --timing --against-python 20 --out bench/results/nmpc-c
	$(PY) -m runtime identify-bench
	$(MAKE) sweep-bench

# Sweep throughput on Dask (1 and 2 workers), overhead against the C batch, per-task cost, bytes
# per result: bench/results/sweep/<date>.json (docs/sweeps.md).
sweep-bench: $(STAMP)
	$(PY) -m runtime sweep-bench

figures: $(STAMP)
	$(PY) -m runtime figures

# docs/estimation.md's frames and estimate figures (a minute), and its consistency study: 50 seeded
# runs per shipped task with fixes and 20 without, on Dask (about an hour on 2 cores), the
# summaries under out/consistency/, the figures copied to docs/figures/.
estimation-figures: $(STAMP)
	$(PY) -m runtime estimation-figures

CONSISTENCY_RUNS ?= 50
consistency: $(STAMP)
	for task in circle figure8 line; do \
	  $(PY) -m runtime consistency $$task --runs $(CONSISTENCY_RUNS) --accel-noise held --out out/consistency/$$task-default; \
	  cp out/consistency/$$task-default/consistency.png docs/figures/consistency-$$task-default.png; \
	done
	$(PY) -m runtime consistency circle --runs 20 --sensors imu-encoders --accel-noise held --out out/consistency/circle-imu-encoders
	cp out/consistency/circle-imu-encoders/consistency.png docs/figures/consistency-circle-imu-encoders.png

# Every controller on every benchmark task: out/control/table.md, table.csv, a folder per run; then the
# offset table (out/control/offsets.md, .csv: docs/control.md, "Offset-free tracking").
control: $(STAMP)
	$(PY) -m runtime control --out out/control
	$(PY) -m runtime control --offsets --out out/control

# The envelope of docs/control.md (prints its numbers, rewrites docs/figures/control-envelope.png).
envelope: $(STAMP)
	$(PY) -m runtime envelope

# The API reference (docs/api.md): pdoc over the Python package into out/docs/python/, Doxygen
# over the public C header into out/docs/c/ (installed from Debian when missing and we are root).
# A warning of either fails the build.
docs: $(STAMP)
	rm -rf out/docs
	mkdir -p out/docs
	$(PY) docs/build_python_api.py out/docs/python runtime
	command -v doxygen >/dev/null || bash .ci/install-doxygen
	doxygen docs/Doxyfile

# The robot as FMI 2.0 and FMI 3.0 co-simulation FMUs: out/fmu/SphericalRobot.fmu and
# out/fmu/fmi3/SphericalRobot.fmu (docs/interop.md).
fmu: $(STAMP)
	$(PY) -m runtime export fmu --out out/fmu

soak: $(STAMP)
	$(PY) -m runtime soak

fuzz:
	$(MAKE) -C c fuzz
	if command -v clang >/dev/null; then $(MAKE) -C c fuzz-libfuzzer; fi

c-lib:
	$(MAKE) -C c

c-test:
	$(MAKE) -C c test sanitize

clean:
	$(MAKE) -C c clean
	rm -rf $(VENV) build out *.egg-info bindings/_sr*.so bindings/_sr.c bindings/_fastcall*.so
