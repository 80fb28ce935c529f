/* gyro_host.c: driving gyro_interface_axi from firmware (a soft CPU, or a
 * Linux process with the slave's page mapped by mmap).
 *
 *   gyrocal registers --config device.toml --format c > gyro_plan.h
 *   cc -std=c99 -I verilog-out -I . -c gyro_host.c
 *
 * gyro_interface_regs.h (verilog-out/, generated from the same Rust table as
 * the slave's decoding) gives the offsets; gyro_plan.h gives the words of a
 * device's readout and calibration settings, in write order (MOD_STEP_LO
 * before MOD_STEP_HI, the drive amplitudes last). Built with
 * -DGYRO_HOST_SELFTEST it runs its own checks against a register file in
 * memory (tests/board_example.rs). */

#include <stddef.h>
#include <stdint.h>

#include "gyro_interface_regs.h"
#include "gyro_plan.h"

static uint32_t gyro_rd(volatile uint32_t *base, uint32_t offset)
{
    return base[offset / 4u];
}

static void gyro_wr(volatile uint32_t *base, uint32_t offset, uint32_t value)
{
    base[offset / 4u] = value;
}

/* 1 when the slave at base is a gyro_interface_axi of this header's major
 * register-map version. */
int gyro_probe(volatile uint32_t *base)
{
    return gyro_rd(base, GYRO_ID_OFFSET) == GYRO_ID_VALUE &&
           (gyro_rd(base, GYRO_VERSION_OFFSET) >> 16) == (GYRO_VERSION_VALUE >> 16);
}

/* The carrier profile the core was built with (GYRO_PROFILE_TABLE or
 * GYRO_PROFILE_FINE), or -1 from a core of a map older than PROFILE, which
 * cannot say. The words gyro_plan.h's device predicts depend on it: compare
 * it with the profile `gyrocal registers` planned for. */
int gyro_profile(volatile uint32_t *base)
{
    if ((gyro_rd(base, GYRO_VERSION_OFFSET) & 0xffffu) < GYRO_PROFILE_SINCE_MINOR) {
        return -1;
    }
    return (int)(gyro_rd(base, GYRO_PROFILE_OFFSET) & GYRO_PROFILE_MASK);
}

/* Write a block of gyro_plan.h, in order. */
void gyro_program(volatile uint32_t *base, const unsigned long (*writes)[2], size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        gyro_wr(base, (uint32_t)writes[i][0], (uint32_t)writes[i][1]);
    }
}

#define GYRO_PROGRAM(base, block) \
    gyro_program((base), (block), sizeof(block) / sizeof((block)[0]))

/* A 40-bit z from its latched words: HI is read sign-extended to 32 bits,
 * so z = HI * 2^32 + LO, in mixer LSB x 256 (8 fractional bits). */
static int64_t gyro_z(uint32_t hi, uint32_t lo)
{
    return (int64_t)(int32_t)hi * 4294967296LL + (int64_t)lo;
}

/* One coherent sample: reading SAMPLE_COUNT latches z1 and z2 at the same
 * clock edge; returns that count. */
uint32_t gyro_read_z(volatile uint32_t *base, int64_t *z1, int64_t *z2)
{
    uint32_t count = gyro_rd(base, GYRO_SAMPLE_COUNT_OFFSET);
    *z1 = gyro_z(gyro_rd(base, GYRO_Z1_HI_OFFSET), gyro_rd(base, GYRO_Z1_LO_OFFSET));
    *z2 = gyro_z(gyro_rd(base, GYRO_Z2_HI_OFFSET), gyro_rd(base, GYRO_Z2_LO_OFFSET));
    return count;
}

/* The next sample after count `last` (busy-waits for the count to move). */
uint32_t gyro_next_z(volatile uint32_t *base, uint32_t last, int64_t *z1, int64_t *z2)
{
    uint32_t count;
    do {
        count = gyro_read_z(base, z1, z2);
    } while (count == last);
    return count;
}

#ifdef GYRO_HOST_SELFTEST
#include <stdio.h>

static uint32_t fake[64];

int main(void)
{
    volatile uint32_t *base = fake;
    int64_t z1, z2;
    size_t i;
    int failures = 0;

    fake[GYRO_ID_OFFSET / 4u] = GYRO_ID_VALUE;
    fake[GYRO_VERSION_OFFSET / 4u] = GYRO_VERSION_VALUE;
    if (!gyro_probe(base)) {
        puts("probe failed");
        failures++;
    }
    fake[GYRO_PROFILE_OFFSET / 4u] = GYRO_PROFILE_FINE;
    if (gyro_profile(base) != (int)GYRO_PROFILE_FINE) {
        puts("PROFILE not read");
        failures++;
    }
    fake[GYRO_VERSION_OFFSET / 4u] = (GYRO_VERSION_VALUE & 0xffff0000u) | (GYRO_PROFILE_SINCE_MINOR - 1u);
    if (gyro_profile(base) != -1 || !gyro_probe(base)) {
        puts("an older minor version: PROFILE read, or the core refused");
        failures++;
    }
    fake[GYRO_VERSION_OFFSET / 4u] = GYRO_VERSION_VALUE;
    GYRO_PROGRAM(base, gyro_readout);
    for (i = 0; i < sizeof(gyro_readout) / sizeof(gyro_readout[0]); i++) {
        if (fake[gyro_readout[i][0] / 4u] != (uint32_t)gyro_readout[i][1]) {
            printf("word %lu not written\n", (unsigned long)i);
            failures++;
        }
    }
    if (fake[GYRO_SELECT_OFFSET / 4u] != 0u) {
        puts("readout block left SELECT set");
        failures++;
    }
    GYRO_PROGRAM(base, gyro_calibration_0);
    if (fake[GYRO_SELECT_OFFSET / 4u] != 1u) {
        puts("calibration block did not set SELECT");
        failures++;
    }
    /* z1 = -128 * 2^32 + 1 (HI sign-extended by the slave), z2 = 2^39 - 1. */
    fake[GYRO_SAMPLE_COUNT_OFFSET / 4u] = 7u;
    fake[GYRO_Z1_HI_OFFSET / 4u] = 0xffffff80u;
    fake[GYRO_Z1_LO_OFFSET / 4u] = 1u;
    fake[GYRO_Z2_HI_OFFSET / 4u] = 0x7fu;
    fake[GYRO_Z2_LO_OFFSET / 4u] = 0xffffffffu;
    if (gyro_next_z(base, 6u, &z1, &z2) != 7u || z1 != -549755813887LL || z2 != 549755813887LL) {
        printf("z assembly: z1 %lld z2 %lld\n", (long long)z1, (long long)z2);
        failures++;
    }
    if (failures == 0) {
        puts("gyro_host self-test: ok");
    }
    return failures != 0;
}
#endif
