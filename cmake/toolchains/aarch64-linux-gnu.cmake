# SPDX-License-Identifier: BSD-2-Clause
# Linux aarch64 with Debian's gcc/g++-aarch64-linux-gnu, run through
# qemu-user (qemu-aarch64 with the cross sysroot as its library root).
# Used by cmake/Platforms.cmake for the aarch64 sub-build.
#
# No fused multiply-add, so that aarch64 rounds like x86-64 (SSE2, no FMA):
# -ffp-contract=off (GCC contracts a*b+c into fmadd by default on aarch64)
# and -U__ARM_FEATURE_FMA (Eigen's NEON kernels call vfmaq_f64 whenever the
# compiler announces FMA, whatever the contraction mode).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
include(${CMAKE_CURRENT_LIST_DIR}/cross_common.cmake)
pkm_cross_find_root(/usr/aarch64-linux-gnu)

set(CMAKE_C_FLAGS_INIT "-ffp-contract=off")
set(CMAKE_CXX_FLAGS_INIT "-ffp-contract=off -U__ARM_FEATURE_FMA")

find_program(PKM_QEMU_AARCH64 NAMES qemu-aarch64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${PKM_QEMU_AARCH64} -L /usr/aarch64-linux-gnu)
