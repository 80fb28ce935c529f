// axi_formal.sv: the property harness of `gyro_interface_axi` (the bus
// wrapper of verilog-out/gyro_interface_axi.v with its DSP core replaced by
// a stub with the same ports, whose z1, z2, z_valid are free on every clock:
// verify/src/formal/stub.rs).
//
// Written from the documented behaviour (README "The bus-attached top",
// verilog-out/REGISTERS.md, hdl/src/host/axi_top.rs), not from the Verilog.
//
//  free inputs ──► s_axil_* (master, assumed to follow AXI) ──► gyro_interface_axi ──► s_axil_b*/r*
//                  m_axis_tready (anything)                      │  core stub: z1, z2,  └─► m_axis_t*
//                  f_pick (which sample to follow)                │  z_valid = $anyseq
//                                                                 ▼
//  reference model here: pending AW/W/AR, the settings as written, the sample count,
//  the ADC_CLIP counts (adc1, adc2 free), the stream FIFO's occupancy and drops;
//  assertions compare the ports with it.
//
// Two kinds of assertion, each with a label that sby reports when it fails:
//  * spec_*: the claims (handshakes, one response per request, SLVERR, read
//    data, reset, the stream). Each is shown failing on a mutant of the
//    export (verify/src/formal.rs, tests/formal.rs).
//  * inv_*: helper invariants that tie the reference model to the DUT's
//    internal state, so that k-induction closes. The mutant runs remove them
//    (a mutant must be caught by a spec_* property).
// Internal signals are read through the probe wires p_* below, driven by
// probes.ys (Yosys `connect` after `flatten`): the core stub's outputs,
// and state that only the inv_* helpers and two stream claims use.
//
// Time: one step per clock (sby's default single-clock mode); every
// register below is a posedge aclk register like the DUT's, with a
// power-up value, and every property is checked from power-up on.

`default_nettype none

module axi_formal (
    input wire aclk,
    input wire aresetn,
    input wire s_axil_awvalid,
    input wire [7:0] s_axil_awaddr,
    input wire s_axil_wvalid,
    input wire [31:0] s_axil_wdata,
    input wire [3:0] s_axil_wstrb,
    input wire s_axil_bready,
    input wire s_axil_arvalid,
    input wire [7:0] s_axil_araddr,
    input wire s_axil_rready,
    input wire m_axis_tready,
    input wire signed [15:0] adc1,
    input wire signed [15:0] adc2,
    // The free choice of the one accepted sample whose journey through the
    // FIFO is followed (any sample, since the solver chooses).
    input wire f_pick
);
    localparam [1:0] OKAY = 2'b00, SLVERR = 2'b10;
    localparam [31:0] ID_WORD = 32'h4759524f, VERSION_WORD = 32'h00010002;
    // PROFILE of the bus proven here, the table core's (gyro_interface_axi.v).
    localparam [31:0] PROFILE_WORD = 32'd0;
    localparam [8:0] FIFO_DEPTH = 9'd256;
    // Word indices (byte offset / 4) of REGISTERS.md.
    localparam [5:0] I_STREAM_ENABLE = 6'd16, I_STREAM_OVERFLOW = 6'd17, I_SAMPLE_COUNT = 6'd18,
        I_Z1_LO = 6'd19, I_Z1_HI = 6'd20, I_Z2_LO = 6'd21, I_Z2_HI = 6'd22, I_ADC_CLIP = 6'd23,
        I_PROFILE = 6'd24;
    localparam [15:0] CLIP_MAX = 16'hffff;

    wire s_axil_awready, s_axil_wready, s_axil_bvalid, s_axil_arready, s_axil_rvalid;
    wire [1:0] s_axil_bresp, s_axil_rresp;
    wire [31:0] s_axil_rdata;
    wire m_axis_tvalid, m_axis_tlast;
    wire [95:0] m_axis_tdata;
    wire signed [15:0] dac1, dac2;

    gyro_interface_axi dut (
        .aclk(aclk), .aresetn(aresetn), .adc1(adc1), .adc2(adc2), .dac1(dac1), .dac2(dac2),
        .s_axil_awvalid(s_axil_awvalid), .s_axil_awready(s_axil_awready),
        .s_axil_awaddr(s_axil_awaddr),
        .s_axil_wvalid(s_axil_wvalid), .s_axil_wready(s_axil_wready),
        .s_axil_wdata(s_axil_wdata), .s_axil_wstrb(s_axil_wstrb),
        .s_axil_bvalid(s_axil_bvalid), .s_axil_bready(s_axil_bready),
        .s_axil_bresp(s_axil_bresp),
        .s_axil_arvalid(s_axil_arvalid), .s_axil_arready(s_axil_arready),
        .s_axil_araddr(s_axil_araddr),
        .s_axil_rvalid(s_axil_rvalid), .s_axil_rready(s_axil_rready),
        .s_axil_rdata(s_axil_rdata), .s_axil_rresp(s_axil_rresp),
        .m_axis_tvalid(m_axis_tvalid), .m_axis_tready(m_axis_tready),
        .m_axis_tdata(m_axis_tdata), .m_axis_tlast(m_axis_tlast)
    );

    // ---- Probes (driven by probes.ys) -------------------------------------
    // The core stub's outputs: what the datapath offers this clock.
    wire [39:0] p_z1, p_z2;
    wire p_z_valid;
    // The fifteen settings fields, settings$0..14 value (SELECT .. STREAM_ENABLE,
    // word index i + 2 at [32 i +: 32]); used by the inv_settings helper.
    wire [15*32-1:0] p_settings;
    // The FIFO's fill count and STREAM_OVERFLOW's counter: spec_t_held_count
    // and spec_t_overflow state the conservation law with them.
    wire [8:0] p_fifo_count;
    wire [31:0] p_overflow_count;
    // ADC_CLIP's two counters (ADC1, ADC2): used by the inv_clip helper.
    wire [15:0] p_clip1, p_clip2;
    // Internal state used only by the inv_* helpers.
    wire p_aw_held, p_w_held, p_ar_held;
    wire [5:0] p_aw_index, p_ar_index;
    wire [31:0] p_w_data;
    wire [3:0] p_w_strb;
    wire [31:0] p_sample_count;
    wire [39:0] p_snapshot_z1, p_snapshot_z2;
    wire [7:0] p_write_ptr, p_read_ptr;
    wire p_fetching, p_out_valid;
    wire [95:0] p_mem_q;
    // The FIFO's RAM (dut.fifo.memory.words): this memory has no port of
    // its own; probes.ys turns its one read port into a read port of the
    // DUT's RAM (same width and depth), so fifo_words[a] is the DUT's word a.
    reg [95:0] fifo_words [0:255];

    // ---- The register map (REGISTERS.md) ----------------------------------
    // 0 unmapped, 1 read-write setting, 2 read-only status.
    function automatic [1:0] kind(input [5:0] idx);
        if (idx <= 6'd1) kind = 2'd2;
        else if (idx <= 6'd16) kind = 2'd1;
        else if (idx <= I_PROFILE) kind = 2'd2;
        else kind = 2'd0;
    endfunction
    // The bits a setting keeps.
    function automatic [31:0] field_mask(input [5:0] idx);
        case (idx)
            6'd2, 6'd16: field_mask = 32'h1;             // SELECT, STREAM_ENABLE
            6'd5, 6'd11: field_mask = 32'h3f;            // REF_DELAY, CIC_SHIFT
            6'd7, 6'd8, 6'd9: field_mask = 32'hffff;     // MOD_STEP_HI, AMP1, AMP2
            6'd10: field_mask = 32'h1fff;                // CIC_DECIMATION
            default: field_mask = 32'hffffffff;          // the 32-bit words
        endcase
    endfunction
    // Signed settings: AMP1, AMP2, IIR_K0..IIR_ALPHA.
    function automatic is_signed(input [5:0] idx);
        is_signed = idx == 6'd8 || idx == 6'd9 || (idx >= 6'd12 && idx <= 6'd15);
    endfunction
    // A field as a read returns it: zero- or sign-extended.
    function automatic [31:0] extend(input [5:0] idx, input [31:0] field);
        reg [31:0] m;
        begin
            m = field_mask(idx);
            extend = (is_signed(idx) && (field & (m & ~(m >> 1))) != 0) ? (field | ~m) : field;
        end
    endfunction
    function automatic [31:0] strobe_mask(input [3:0] strb);
        strobe_mask = {{8{strb[3]}}, {8{strb[2]}}, {8{strb[1]}}, {8{strb[0]}}};
    endfunction

    // ---- Handshakes --------------------------------------------------------
    wire aw_hs = s_axil_awvalid && s_axil_awready;
    wire w_hs = s_axil_wvalid && s_axil_wready;
    wire b_hs = s_axil_bvalid && s_axil_bready;
    wire ar_hs = s_axil_arvalid && s_axil_arready;
    wire r_hs = s_axil_rvalid && s_axil_rready;
    wire t_hs = m_axis_tvalid && m_axis_tready;

    reg f_reset_q = 1'b0;    // aresetn was low at the previous clock
    reg b_stall = 1'b0, r_stall = 1'b0, t_stall = 1'b0; // VALID && !READY at the previous clock
    reg [1:0] bresp_q = 2'd0, rresp_q = 2'd0;
    reg [31:0] rdata_q = 32'd0;
    reg [95:0] tdata_q = 96'd0;
    always @(posedge aclk) begin
        f_reset_q <= !aresetn;
        b_stall <= aresetn && s_axil_bvalid && !s_axil_bready;
        r_stall <= aresetn && s_axil_rvalid && !s_axil_rready;
        t_stall <= aresetn && m_axis_tvalid && !m_axis_tready;
        bresp_q <= s_axil_bresp;
        rresp_q <= s_axil_rresp;
        rdata_q <= s_axil_rdata;
        tdata_q <= m_axis_tdata;
    end
    // A response appears: VALID now, and not a held one.
    wire new_b = s_axil_bvalid && !b_stall;
    wire new_r = s_axil_rvalid && !r_stall;

    // ---- The master follows AXI (assumptions) -------------------------------
    reg aw_wait = 1'b0, w_wait = 1'b0, ar_wait = 1'b0;
    reg [7:0] awaddr_q = 8'd0, araddr_q = 8'd0;
    reg [31:0] wdata_q = 32'd0;
    reg [3:0] wstrb_q = 4'd0;
    always @(posedge aclk) begin
        aw_wait <= aresetn && s_axil_awvalid && !s_axil_awready;
        w_wait <= aresetn && s_axil_wvalid && !s_axil_wready;
        ar_wait <= aresetn && s_axil_arvalid && !s_axil_arready;
        awaddr_q <= s_axil_awaddr;
        wdata_q <= s_axil_wdata;
        wstrb_q <= s_axil_wstrb;
        araddr_q <= s_axil_araddr;
    end
    always @(*) begin
        // VALID low while aresetn is low.
        if (!aresetn) assume (!s_axil_awvalid && !s_axil_wvalid && !s_axil_arvalid);
        // A VALID is held until READY, its payload unchanged.
        if (aw_wait && aresetn) assume (s_axil_awvalid && s_axil_awaddr == awaddr_q);
        if (w_wait && aresetn)
            assume (s_axil_wvalid && s_axil_wdata == wdata_q && s_axil_wstrb == wstrb_q);
        if (ar_wait && aresetn) assume (s_axil_arvalid && s_axil_araddr == araddr_q);
    end

    // ---- Reference model: requests waiting for their response --------------
    // aw_n, w_n, ar_n: requests accepted whose response has not appeared yet
    // (at most one each: the slave holds one address and one data word);
    // q_*: the oldest such request.
    reg aw_n = 1'b0, w_n = 1'b0, ar_n = 1'b0;
    reg [5:0] q_aw = 6'd0, q_ar = 6'd0;
    reg [31:0] q_wdata = 32'd0;
    reg [3:0] q_wstrb = 4'd0;
    always @(posedge aclk) begin
        if (!aresetn) begin
            aw_n <= 1'b0;
            w_n <= 1'b0;
            ar_n <= 1'b0;
        end else begin
            aw_n <= (aw_n && !new_b) || aw_hs;
            w_n <= (w_n && !new_b) || w_hs;
            ar_n <= (ar_n && !new_r) || ar_hs;
        end
        if (aw_hs) q_aw <= s_axil_awaddr[7:2];
        if (w_hs) begin
            q_wdata <= s_axil_wdata;
            q_wstrb <= s_axil_wstrb;
        end
        if (ar_hs) q_ar <= s_axil_araddr[7:2];
    end

    // ---- Reference model: the settings -------------------------------------
    // setting[i].value: setting i as written by the responses seen so far;
    // cur: as it stands this clock (a write takes effect at the edge before its
    // response appears, so a response appearing now shows its write).
    wire [15*32-1:0] cur;
    wire write_now = new_b && aw_n && w_n && kind(q_aw) == 2'd1;
    genvar gi;
    generate
        for (gi = 0; gi < 15; gi = gi + 1) begin : setting
            localparam [5:0] IDX = gi + 2;
            localparam [31:0] POWER_UP = (IDX == 6'd10) ? 32'd256 : (IDX == 6'd11) ? 32'd24 : 32'd0;
            reg [31:0] value = POWER_UP;
            assign cur[gi*32 +: 32] = (write_now && q_aw == IDX)
                ? (((value & ~strobe_mask(q_wstrb)) | (q_wdata & strobe_mask(q_wstrb)))
                   & field_mask(IDX))
                : value;
            always @(posedge aclk) value <= aresetn ? cur[gi*32 +: 32] : POWER_UP;
        end
    endgenerate
    wire stream_enable = cur[(I_STREAM_ENABLE - 2)*32];

    // ---- Reference model: samples, the snapshot, the stream FIFO -----------
    // count: z_valid clocks since power-up or reset; drops: samples offered
    // while occ = 256; occ: samples offered, not delivered, not dropped.
    reg [31:0] count = 32'd0, drops = 32'd0;
    reg [8:0] occ = 9'd0;
    reg [39:0] z1_q = 40'd0, z2_q = 40'd0, snap1 = 40'd0, snap2 = 40'd0;
    wire offered = p_z_valid && stream_enable;
    wire full = occ == FIFO_DEPTH;
    wire accepted = offered && !full;
    wire [31:0] count_now = count + p_z_valid;        // SAMPLE_COUNT includes this clock's sample
    wire [95:0] sample = {count_now[15:0], p_z2, p_z1}; // the beat this clock's sample must become
    // The snapshot as it stands: a SAMPLE_COUNT read latched z at the edge
    // before its data appeared.
    wire snap_now = new_r && ar_n && q_ar == I_SAMPLE_COUNT;
    wire [39:0] snap1_cur = snap_now ? z1_q : snap1;
    wire [39:0] snap2_cur = snap_now ? z2_q : snap2;
    always @(posedge aclk) begin
        z1_q <= p_z1;
        z2_q <= p_z2;
        if (!aresetn) begin
            count <= 32'd0;
            drops <= 32'd0;
            occ <= 9'd0;
            snap1 <= 40'd0;
            snap2 <= 40'd0;
        end else begin
            count <= count_now;
            drops <= drops + (offered && full);
            occ <= occ + accepted - t_hs;
            snap1 <= snap1_cur;
            snap2 <= snap2_cur;
        end
    end

    // ---- Reference model: ADC_CLIP ------------------------------------------
    // clip1, clip2: the rail-code clocks of ADC1, ADC2 counted up to the last
    // edge, saturating at 65535, as if that edge read no ADC_CLIP; a read at
    // that edge (its data appearing now: clip_read) restarted them instead,
    // with that edge's rail code counted (rail*_q). clip*_cur: as they stand
    // this clock, which a read performed at this edge returns.
    // A word at a rail: within 1/128 of full scale (top byte 0x7f or 0x80),
    // where every rail code of an 8- to 16-bit converter lies (the words
    // are left-justified: a 12-bit converter's positive rail is +32752).
    wire rail1 = adc1[15:8] == 8'h7f || adc1[15:8] == 8'h80;
    wire rail2 = adc2[15:8] == 8'h7f || adc2[15:8] == 8'h80;
    reg rail1_q = 1'b0, rail2_q = 1'b0;
    reg [15:0] clip1 = 16'd0, clip2 = 16'd0;
    wire clip_read = new_r && ar_n && q_ar == I_ADC_CLIP;
    wire [15:0] clip1_cur = clip_read ? {15'd0, rail1_q} : clip1;
    wire [15:0] clip2_cur = clip_read ? {15'd0, rail2_q} : clip2;
    always @(posedge aclk) begin
        rail1_q <= rail1;
        rail2_q <= rail2;
        if (!aresetn) begin
            clip1 <= 16'd0;
            clip2 <= 16'd0;
        end else begin
            clip1 <= clip1_cur + (rail1 && clip1_cur != CLIP_MAX);
            clip2 <= clip2_cur + (rail2 && clip2_cur != CLIP_MAX);
        end
    end

    // One accepted sample, chosen by f_pick, followed to the stream: pos is
    // the number of samples ahead of it.
    reg trk = 1'b0;
    reg [8:0] pos = 9'd0;
    reg [95:0] trk_data = 96'd0;
    always @(posedge aclk) begin
        if (!aresetn) trk <= 1'b0;
        else if (trk) begin
            if (t_hs) begin
                if (pos == 9'd0) trk <= 1'b0;
                else pos <= pos - 9'd1;
            end
        end else if (accepted && f_pick) begin
            trk <= 1'b1;
            pos <= occ - t_hs;
            trk_data <= sample;
        end
    end

    // ---- What a read returns ------------------------------------------------
    // The word at index idx this clock; a read performed at this edge
    // returns it with its response at the next clock.
    function automatic [31:0] sext8(input [7:0] b);
        sext8 = {{24{b[7]}}, b};
    endfunction
    reg [31:0] expect_word;
    integer k;
    always @(*) begin
        expect_word = 32'd0;
        for (k = 0; k < 15; k = k + 1)
            if (q_ar == k + 2) expect_word = extend(k + 2, cur[k*32 +: 32]);
        case (q_ar)
            6'd0: expect_word = ID_WORD;
            6'd1: expect_word = VERSION_WORD;
            I_STREAM_OVERFLOW: expect_word = drops;
            I_SAMPLE_COUNT: expect_word = count_now;
            I_Z1_LO: expect_word = snap1_cur[31:0];
            I_Z1_HI: expect_word = sext8(snap1_cur[39:32]);
            I_Z2_LO: expect_word = snap2_cur[31:0];
            I_Z2_HI: expect_word = sext8(snap2_cur[39:32]);
            I_ADC_CLIP: expect_word = {clip2_cur, clip1_cur};
            I_PROFILE: expect_word = PROFILE_WORD;
            default: ;
        endcase
    end
    reg [31:0] expect_q = 32'd0;
    always @(posedge aclk) expect_q <= expect_word;

    // ---- Properties -----------------------------------------------------------
    reg clip_seen = 1'b0;   // an ADC_CLIP read has answered before (cover_clip)
    always @(posedge aclk) clip_seen <= clip_seen || clip_read;
    reg [1:0] idle = 2'd0;  // consecutive clocks with occ > 0 and no TVALID
    reg b_due = 1'b0, r_due = 1'b0; // a request waited with its channel free
    always @(posedge aclk) begin
        idle <= (aresetn && occ != 9'd0 && !m_axis_tvalid) ? idle + 2'd1 : 2'd0;
        b_due <= aresetn && aw_n && w_n && !s_axil_bvalid;
        r_due <= aresetn && ar_n && !s_axil_rvalid;
    end

    always @(*) begin
        // Reset (synchronous): the clock after aresetn low offers no response
        // and no beat, and takes every request. (Settings back at power-up,
        // counters and snapshot 0, FIFO empty: the model resets too, and the
        // read-data and stream properties below compare against it.)
        if (f_reset_q)
            spec_reset: assert (!s_axil_bvalid && !s_axil_rvalid && !m_axis_tvalid
                && s_axil_awready && s_axil_wready && s_axil_arready);

        // B: BVALID held until BREADY, BRESP unchanged.
        if (b_stall)
            spec_b_held: assert (s_axil_bvalid && s_axil_bresp == bresp_q);
        // B: no response without an accepted AW and W waiting for it.
        if (new_b)
            spec_b_requested: assert (aw_n && w_n);
        // B: a waiting AW and W are answered the clock after B is free
        // (never lost, never hung).
        if (b_due) spec_b_answers: assert (new_b);
        // B: SLVERR for an unmapped or read-only offset, OKAY for a setting.
        if (new_b && aw_n)
            spec_b_resp: assert (s_axil_bresp == ((kind(q_aw) == 2'd1) ? OKAY : SLVERR));
        // AW, W: at most one waits; with none waiting the slave is ready.
        spec_aw_one: assert (!(aw_hs && aw_n && !new_b));
        spec_w_one: assert (!(w_hs && w_n && !new_b));
        if (!aw_n) spec_aw_ready: assert (s_axil_awready);
        if (!w_n) spec_w_ready: assert (s_axil_wready);

        // R: RVALID held until RREADY, RDATA and RRESP unchanged.
        if (r_stall)
            spec_r_held: assert (s_axil_rvalid && s_axil_rdata == rdata_q
                && s_axil_rresp == rresp_q);
        // R: no read data without an accepted AR.
        if (new_r) spec_r_requested: assert (ar_n);
        // R: a waiting AR is answered the clock after R is free.
        if (r_due) spec_r_answers: assert (new_r);
        // R: SLVERR for an unmapped offset, else OKAY with the register's
        // value at the edge that performed the read.
        if (new_r && ar_n) begin
            spec_r_resp: assert (s_axil_rresp == ((kind(q_ar) == 2'd0) ? SLVERR : OKAY));
            if (kind(q_ar) != 2'd0 && q_ar != I_ADC_CLIP)
                spec_r_data: assert (s_axil_rdata == expect_q);
            // ADC_CLIP: the two saturating counts since the last read of it
            // (or power-up, or reset), the read restarting them.
            if (q_ar == I_ADC_CLIP) spec_clip: assert (s_axil_rdata == expect_q);
        end
        spec_ar_one: assert (!(ar_hs && ar_n && !new_r));
        if (!ar_n) spec_ar_ready: assert (s_axil_arready);
    end

    always @(*) begin
        // Stream: TVALID held until TREADY, TDATA unchanged; TLAST = 1.
        if (t_stall) spec_t_held: assert (m_axis_tvalid && m_axis_tdata == tdata_q);
        if (m_axis_tvalid) spec_t_last: assert (m_axis_tlast);
        // Stream: no beat without an undelivered sample (nothing repeated or
        // invented).
        if (m_axis_tvalid) spec_t_sample: assert (occ != 9'd0);
        // Stream: a held sample is offered within 2 clocks (nothing stuck).
        if (aresetn && occ != 9'd0 && !m_axis_tvalid) spec_t_offered: assert (idle < 2'd2);
        // Stream: the followed sample leaves as the beat its position says,
        // unchanged, with its sample count: nothing lost, reordered, or
        // repeated, and TDATA 95..80 = SAMPLE_COUNT of that sample.
        if (trk && pos == 9'd0 && m_axis_tvalid) spec_t_data: assert (m_axis_tdata == trk_data);
        // Stream: offered = delivered + held + dropped, the FIFO holding
        // exactly the model's occupancy and STREAM_OVERFLOW counting exactly
        // the samples offered while 256 were held.
        spec_t_held_count: assert (p_fifo_count == occ);
        spec_t_overflow: assert (p_overflow_count == drops);
    end

    // ---- Reachability (task cover): the claims are not vacuous ---------------
    always @(*) begin
        // A setting written (OKAY), and AMP1 read back as -32768, sign-extended.
        cover_write_okay: cover (new_b && aw_n && kind(q_aw) == 2'd1 && s_axil_bresp == OKAY);
        cover_read_setting: cover (new_r && ar_n && q_ar == 6'd8 && s_axil_rdata == 32'hffff8000);
        // SLVERR for a write to a read-only word.
        cover_write_slverr: cover (new_b && aw_n && kind(q_aw) == 2'd2);
        // A z snapshot read back non-zero.
        cover_read_snapshot: cover (new_r && ar_n && q_ar == I_Z1_HI && s_axil_rdata != 32'd0);
        // Each channel stalled, then taken.
        cover_b_stall: cover (b_stall && s_axil_bready);
        cover_r_stall: cover (r_stall && s_axil_rready);
        cover_t_stall: cover (t_stall && m_axis_tready);
        // The followed sample taken with another one ahead of it first.
        cover_followed: cover (trk && pos == 9'd1 && t_hs);
        // A second ADC_CLIP read with both counts non-zero (after a restart).
        cover_clip: cover (clip_read && clip_seen && s_axil_rdata[15:0] != 16'd0
            && s_axil_rdata[31:16] != 16'd0);
        // A reset with a response and a sample in flight.
        cover_reset: cover (!aresetn && s_axil_bvalid && occ != 9'd0);
    end

    // ---- Helper invariants (induction) ---------------------------------------
    wire busy = p_out_valid || p_fetching;
    wire [7:0] trk_addr = p_read_ptr + pos[7:0] - busy; // the followed sample's RAM word
    wire [95:0] trk_word = fifo_words[trk_addr];
    always @(*) begin
        inv_aw: assert (aw_n == (p_aw_held || new_b) && !(p_aw_held && new_b)
            && (!p_aw_held || p_aw_index == q_aw));
        inv_w: assert (w_n == (p_w_held || new_b) && !(p_w_held && new_b)
            && (!p_w_held || (p_w_data == q_wdata && p_w_strb == q_wstrb)));
        inv_ar: assert (ar_n == (p_ar_held || new_r) && !(p_ar_held && new_r)
            && (!p_ar_held || p_ar_index == q_ar));
        inv_settings: assert (p_settings == cur);
        inv_count: assert (p_sample_count == count);
        inv_clip: assert (p_clip1 == clip1_cur && p_clip2 == clip2_cur);
        inv_snapshot: assert (p_snapshot_z1 == snap1_cur && p_snapshot_z2 == snap2_cur);
        inv_fifo: assert (!(p_fetching && p_out_valid) && occ <= FIFO_DEPTH
            && (!busy || occ != 9'd0)
            && p_write_ptr == p_read_ptr + (occ[7:0] - busy) && p_out_valid == m_axis_tvalid);
        if (trk) inv_trk_held: assert (pos < occ);
        if (trk && pos == 9'd0 && p_fetching) inv_trk_fetch: assert (p_mem_q == trk_data);
        if (trk && !(pos == 9'd0 && busy)) inv_trk_ram: assert (trk_word == trk_data);
    end
endmodule
