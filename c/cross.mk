# c/cross.mk -- Cortex-M cross builds under QEMU (included by c/Makefile; docs/embedding.md,
# "Cortex-M targets").
#
#   make cross-test    installs arm-none-eabi-gcc, newlib and qemu-system-arm when it can (root
#                      and apt-get), builds the float library for the Cortex-M4F and the double
#                      library for the Cortex-M7 with this Makefile (CC, AR, CFLAGS, LDFLAGS,
#                      BUILD), runs the C tests and the firmware example on QEMU's mps2-an386
#                      and mps2-an500, compares them with the host builds, checks the float build
#                      for double arithmetic, builds with the CMake toolchain file, and prints
#                      the sizes and stacks; exits non-zero on any mismatch (cross/cross_test.sh)
#   make cross-report  the same sizes and stacks written into ../docs/embedding.md
#
# Variables: CROSS_PREFIX (arm-none-eabi-), QEMU (qemu-system-arm).  The CPU flags of the two
# targets, for your own build of the library:
CROSS_PREFIX ?= arm-none-eabi-
QEMU         ?= qemu-system-arm
M4_CPU_FLAGS := -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
M7_CPU_FLAGS := -mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard

CROSS_ENV = CROSS_PREFIX='$(CROSS_PREFIX)' QEMU='$(QEMU)' MAKE='$(MAKE)' \
            M4_CPU_FLAGS='$(M4_CPU_FLAGS)' M7_CPU_FLAGS='$(M7_CPU_FLAGS)'

.PHONY: cross-test cross-report
cross-test:
	$(CROSS_ENV) sh cross/cross_test.sh $(BUILD)/cross

cross-report:
	python3 ../tools/m4_report.py --build $(BUILD)/cross/report --cross-prefix '$(CROSS_PREFIX)' --qemu '$(QEMU)' \
	    --update ../docs/embedding.md

.PHONY: cross-clean
clean: cross-clean
cross-clean:
	rm -rf $(BUILD)/cross
