// gyro_board_top: gyro_interface_axi (verilog-out/gyro_interface_axi.v) on a
// board with two parallel ADCs and two parallel DACs, the way a design drops
// it in. Linted with the export (tests/verilog_lint.rs); README "Dropping the
// core into an FPGA design" has the Yosys and nextpnr commands.
//
// Clock: one clock for bus, stream and datapath (clk), from the board's PLL:
// 100 MHz on an ECP5 LFE5U-25F, 30 MHz on an iCE40 UP5K (the place-and-route
// targets of verilog-out/RESOURCES.md). The converters run on the same clock.
//
// Converter registers: each converter word crosses one flip-flop at the pins
// (pack them into the I/O cells: Yosys and nextpnr do so for a register
// whose only load or driver is the pad). They add one clock to each path, so
// program
//
//     REF_DELAY = L_dac + L_adc + 2
//
// where L_dac and L_adc are the converters' own pipeline latencies in clocks
// (datasheet), and REF_PHASE = CARRIER_STEP / 2 (REGISTERS.md).
//
// Formats: the core takes and gives two's complement words, full scale
// +-32767. Converters with offset-binary pins (mid-scale = 0x8000) need the
// MSB inverted: set OFFSET_BINARY = 1. A converter narrower than 16 bits sits
// at the MSBs (zero the LSBs).
//
// Reset: resetn (active low, synchronous to clk) returns the AXI wrapper to
// power-up; the datapath core has no reset and simulates from time zero.

`default_nettype none

module gyro_board_top #(
    parameter OFFSET_BINARY = 0  // 1: converters use offset binary pins
) (
    input  wire        clk,
    input  wire        resetn,
    // Converter pins.
    input  wire [15:0] adc1_pins,
    input  wire [15:0] adc2_pins,
    output reg  [15:0] dac1_pins,
    output reg  [15:0] dac2_pins,
    // AXI4-Lite slave to the host's interconnect (8-bit byte address).
    input  wire        s_axil_awvalid,
    output wire        s_axil_awready,
    input  wire [7:0]  s_axil_awaddr,
    input  wire        s_axil_wvalid,
    output wire        s_axil_wready,
    input  wire [31:0] s_axil_wdata,
    input  wire [3:0]  s_axil_wstrb,
    output wire        s_axil_bvalid,
    input  wire        s_axil_bready,
    output wire [1:0]  s_axil_bresp,
    input  wire        s_axil_arvalid,
    output wire        s_axil_arready,
    input  wire [7:0]  s_axil_araddr,
    output wire        s_axil_rvalid,
    input  wire        s_axil_rready,
    output wire [31:0] s_axil_rdata,
    output wire [1:0]  s_axil_rresp,
    // AXI4-Stream master of z samples (to a DMA or a FIFO).
    output wire        m_axis_tvalid,
    input  wire        m_axis_tready,
    output wire [95:0] m_axis_tdata,
    output wire        m_axis_tlast
);
    localparam [15:0] FORMAT = OFFSET_BINARY ? 16'h8000 : 16'h0000;

    // One register per converter path at the pins: +1 clock to L_adc.
    reg signed [15:0] adc1_q = 16'sd0;
    reg signed [15:0] adc2_q = 16'sd0;
    always @(posedge clk) begin
        adc1_q <= adc1_pins ^ FORMAT;
        adc2_q <= adc2_pins ^ FORMAT;
    end

    wire signed [15:0] dac1_word;
    wire signed [15:0] dac2_word;
    // +1 clock to L_dac.
    initial begin
        dac1_pins = FORMAT;
        dac2_pins = FORMAT;
    end
    always @(posedge clk) begin
        dac1_pins <= dac1_word ^ FORMAT;
        dac2_pins <= dac2_word ^ FORMAT;
    end

    gyro_interface_axi gyro (
        .aclk(clk),
        .aresetn(resetn),
        .adc1(adc1_q),
        .adc2(adc2_q),
        .dac1(dac1_word),
        .dac2(dac2_word),
        .s_axil_awvalid(s_axil_awvalid),
        .s_axil_awready(s_axil_awready),
        .s_axil_awaddr(s_axil_awaddr),
        .s_axil_wvalid(s_axil_wvalid),
        .s_axil_wready(s_axil_wready),
        .s_axil_wdata(s_axil_wdata),
        .s_axil_wstrb(s_axil_wstrb),
        .s_axil_bvalid(s_axil_bvalid),
        .s_axil_bready(s_axil_bready),
        .s_axil_bresp(s_axil_bresp),
        .s_axil_arvalid(s_axil_arvalid),
        .s_axil_arready(s_axil_arready),
        .s_axil_araddr(s_axil_araddr),
        .s_axil_rvalid(s_axil_rvalid),
        .s_axil_rready(s_axil_rready),
        .s_axil_rdata(s_axil_rdata),
        .s_axil_rresp(s_axil_rresp),
        .m_axis_tvalid(m_axis_tvalid),
        .m_axis_tready(m_axis_tready),
        .m_axis_tdata(m_axis_tdata),
        .m_axis_tlast(m_axis_tlast)
    );
endmodule

`default_nettype wire
