// C ABI around the Verilated gyro_interface, for gyrocal-sim's `verilator`
// engine. One call steps one clock: inputs set, clock low and settle, clock
// high (the rising edge), outputs read. Signed ports are returned
// sign-extended.
//
// Compiled once per core (build.rs): the two cores' Verilog files have the
// same module name, so each is Verilated with its own `--prefix`, and this
// file names the model's classes and its own functions from the macros
//   GYROCAL_VMODEL        the model class (Vgyro_interface, Vgyro_interface_fine)
//   GYROCAL_VMODEL_H      its header, GYROCAL_VROOT_H the root's header
//   GYROCAL_VROOT         the root class
//   GYROCAL_FN(name)      this file's C functions, gyrocal_verilator[_fine]_name
//   GYROCAL_HANDLE        the handle struct, one name per core
#include <cstdint>
#include <memory>
#include "verilated.h"
#include GYROCAL_VMODEL_H
#include GYROCAL_VROOT_H

#define GyrocalVerilator GYROCAL_HANDLE
#define Vgyro_interface GYROCAL_VMODEL
#define Vgyro_interface___024root GYROCAL_VROOT

extern "C" {

struct GyrocalRegisters {
    uint32_t carrier_step;
    uint32_t ref_phase;
    uint64_t mod_step;
    int32_t iir_k0, iir_k1, iir_k2, iir_alpha;
    int16_t amp1, amp2;
    uint16_t cic_decimation;
    uint8_t select, ref_delay, cic_shift;
};

struct GyrocalOutputs {
    int64_t z1, z2;
    int16_t dac1, dac2;
    uint8_t z_valid;
};

struct GyrocalProbes {
    int64_t cic1, cic2;
    int32_t w1, w2;
    int16_t ref1, ref2, am1, am2;
    uint8_t cic_valid;
};

struct GyrocalVerilator {
    std::unique_ptr<VerilatedContext> context;
    std::unique_ptr<Vgyro_interface> model;
};

static inline int64_t sign_extend(uint64_t v, int bits) {
    return static_cast<int64_t>(v << (64 - bits)) >> (64 - bits);
}

GyrocalVerilator* GYROCAL_FN(new)() {
    auto* g = new GyrocalVerilator;
    g->context = std::make_unique<VerilatedContext>();
    g->model = std::make_unique<Vgyro_interface>(g->context.get());
    g->model->clock = 0;
    g->model->eval();  // runs the initial blocks: power-up values
    return g;
}

void GYROCAL_FN(free)(GyrocalVerilator* g) {
    if (g) {
        g->model->final();
        delete g;
    }
}

void GYROCAL_FN(set_registers)(GyrocalVerilator* g, const GyrocalRegisters* r) {
    Vgyro_interface* m = g->model.get();
    m->select = r->select;
    m->carrier_step = r->carrier_step;
    m->ref_phase = r->ref_phase;
    m->ref_delay = r->ref_delay & 0x3f;
    m->mod_step = r->mod_step & 0xffffffffffffULL;
    m->amp1 = static_cast<uint16_t>(r->amp1);
    m->amp2 = static_cast<uint16_t>(r->amp2);
    m->cic_decimation = r->cic_decimation & 0x1fff;
    m->cic_shift = r->cic_shift & 0x3f;
    m->iir_k0 = static_cast<uint32_t>(r->iir_k0);
    m->iir_k1 = static_cast<uint32_t>(r->iir_k1);
    m->iir_k2 = static_cast<uint32_t>(r->iir_k2);
    m->iir_alpha = static_cast<uint32_t>(r->iir_alpha);
}

void GYROCAL_FN(outputs)(const GyrocalVerilator* g, GyrocalOutputs* out) {
    const Vgyro_interface* m = g->model.get();
    out->dac1 = static_cast<int16_t>(m->dac1);
    out->dac2 = static_cast<int16_t>(m->dac2);
    out->z1 = sign_extend(m->z1, 40);
    out->z2 = sign_extend(m->z2, 40);
    out->z_valid = m->z_valid;
}

void GYROCAL_FN(step)(GyrocalVerilator* g, int16_t adc1, int16_t adc2, GyrocalOutputs* out) {
    Vgyro_interface* m = g->model.get();
    m->adc1 = static_cast<uint16_t>(adc1);
    m->adc2 = static_cast<uint16_t>(adc2);
    m->clock = 0;
    m->eval();
    m->clock = 1;
    m->eval();
    GYROCAL_FN(outputs)(g, out);
}

void GYROCAL_FN(probes)(const GyrocalVerilator* g, GyrocalProbes* p) {
    const Vgyro_interface___024root* r = g->model->rootp;
    p->ref1 = static_cast<int16_t>(r->gyro_interface__DOT__am_mixer__DOT__reference1__DOT__y_out__024q);
    p->ref2 = static_cast<int16_t>(r->gyro_interface__DOT__am_mixer__DOT__reference2__DOT__y_out__024q);
    p->w1 = static_cast<int32_t>(r->gyro_interface__DOT__demod_mux__DOT__mixer1__024p);
    p->w2 = static_cast<int32_t>(r->gyro_interface__DOT__demod_mux__DOT__mixer2__024p);
    p->cic1 = sign_extend(r->gyro_interface__DOT__cic__DOT__y1_out__024q, 40);
    p->cic2 = sign_extend(r->gyro_interface__DOT__cic__DOT__y2_out__024q, 40);
    p->cic_valid = r->gyro_interface__DOT__cic__DOT__valid_out__024q;
    p->am1 = static_cast<int16_t>(r->gyro_interface__DOT__modulation_nco__DOT__am1_out__024q);
    p->am2 = static_cast<int16_t>(r->gyro_interface__DOT__modulation_nco__DOT__am2_out__024q);
}

}  // extern "C"
