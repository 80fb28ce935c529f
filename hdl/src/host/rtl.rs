//! The rust-hdl `GyroInterfaceAxi` driven directly, with the model's
//! interface (`super::model::BusInputs` in, `BusOutputs` out, one rising
//! edge per `step`), and the comparison of the two.

use super::axi_top::GyroInterfaceAxi;
use super::model::{self, BusInputs, BusOutputs};
use crate::drive::{prepare, tick};
use crate::primitives::convert::{i128_to_signed, signed_to_i128, u128_to_bits};

/// rust-hdl's simulation of the bus top.
pub struct RtlGyroInterfaceAxi {
    uut: Box<GyroInterfaceAxi>,
}

impl Default for RtlGyroInterfaceAxi {
    fn default() -> Self {
        Self::new()
    }
}

impl RtlGyroInterfaceAxi {
    /// The design at power-up, connected and checked.
    pub fn new() -> Self {
        let mut uut = Box::new(GyroInterfaceAxi::new());
        prepare(uut.as_mut());
        Self { uut }
    }

    /// The output ports during the current cycle.
    pub fn outputs(&self) -> BusOutputs {
        let u = &self.uut;
        BusOutputs {
            dac: (
                signed_to_i128(u.dac1.val()) as i16,
                signed_to_i128(u.dac2.val()) as i16,
            ),
            awready: u.s_axil_awready.val(),
            wready: u.s_axil_wready.val(),
            bvalid: u.s_axil_bvalid.val(),
            bresp: u.s_axil_bresp.val().to_u64() as u8,
            arready: u.s_axil_arready.val(),
            rvalid: u.s_axil_rvalid.val(),
            rdata: u.s_axil_rdata.val().to_u64() as u32,
            rresp: u.s_axil_rresp.val().to_u64() as u8,
            tvalid: u.m_axis_tvalid.val(),
            tdata: u.m_axis_tdata.val().to_u128(),
            tlast: u.m_axis_tlast.val(),
        }
    }

    /// One clock with the inputs `i`.
    pub fn step(&mut self, i: &BusInputs) -> BusOutputs {
        let u = &mut self.uut;
        u.aresetn.next = i.aresetn;
        u.adc1.next = i128_to_signed(i.adc.0 as i128);
        u.adc2.next = i128_to_signed(i.adc.1 as i128);
        u.s_axil_awvalid.next = i.awvalid;
        u.s_axil_awaddr.next = u128_to_bits(i.awaddr as u128);
        u.s_axil_wvalid.next = i.wvalid;
        u.s_axil_wdata.next = u128_to_bits(i.wdata as u128);
        u.s_axil_wstrb.next = u128_to_bits(i.wstrb as u128);
        u.s_axil_bready.next = i.bready;
        u.s_axil_arvalid.next = i.arvalid;
        u.s_axil_araddr.next = u128_to_bits(i.araddr as u128);
        u.s_axil_rready.next = i.rready;
        u.m_axis_tready.next = i.tready;
        tick(u.as_mut());
        self.outputs()
    }
}

/// The first cycle (0 = power-up) on which the rust-hdl design and the
/// model disagree, with both outputs.
pub fn first_mismatch(inputs: &[BusInputs]) -> Option<(usize, BusOutputs, BusOutputs)> {
    let mut rtl = RtlGyroInterfaceAxi::new();
    let mut model = model::GyroInterfaceAxi::new();
    if rtl.outputs() != model.outputs() {
        return Some((0, rtl.outputs(), model.outputs()));
    }
    for (n, i) in inputs.iter().enumerate() {
        let (r, m) = (rtl.step(i), model.step(i));
        if r != m {
            return Some((n + 1, r, m));
        }
    }
    None
}
