// core_stub.v: stands in for `gyro_interface_axi__core` (the DSP datapath)
// in the bus proofs. Every output is unconstrained on every clock
// (`$anyseq`), so a proof over this stub covers any sequence of z1, z2,
// z_valid (and dac1, dac2) the real core could produce, including a z_valid
// on every clock, which the core (one sample per R >= 166 clocks) never does.
// The settings inputs are left unread. Read after the exported Verilog with
// `read_verilog -overwrite`, it replaces the core and its submodules drop
// out of the hierarchy.
module gyro_interface_axi__core(clock, adc1, adc2, dac1, dac2, z1, z2, z_valid, select,
    carrier_step, ref_phase, ref_delay, mod_step, amp1, amp2, cic_decimation, cic_shift,
    iir_k0, iir_k1, iir_k2, iir_alpha);
    input wire clock;
    input wire signed [15:0] adc1;
    input wire signed [15:0] adc2;
    output wire signed [15:0] dac1;
    output wire signed [15:0] dac2;
    output wire signed [39:0] z1;
    output wire signed [39:0] z2;
    output wire z_valid;
    input wire select;
    input wire [31:0] carrier_step;
    input wire [31:0] ref_phase;
    input wire [5:0] ref_delay;
    input wire [47:0] mod_step;
    input wire signed [15:0] amp1;
    input wire signed [15:0] amp2;
    input wire [12:0] cic_decimation;
    input wire [5:0] cic_shift;
    input wire signed [31:0] iir_k0;
    input wire signed [31:0] iir_k1;
    input wire signed [31:0] iir_k2;
    input wire signed [31:0] iir_alpha;
    assign dac1 = $anyseq;
    assign dac2 = $anyseq;
    assign z1 = $anyseq;
    assign z2 = $anyseq;
    assign z_valid = $anyseq;
endmodule
