//! Conversions between rust-hdl's `Signed<N>` / `Bits<N>` and native integers.
//!
//! Only the hand-written leaf blocks (their Rust `update()`) and the test
//! benches use these; the `#[hdl_gen]` blocks never do. Values are taken
//! modulo 2^N (two's complement wrap), like the hardware.

use rust_hdl::prelude::*;

/// Two's complement value of a `Signed<N>` (N <= 128).
pub fn signed_to_i128<const N: usize>(x: Signed<N>) -> i128 {
    bits_to_i128(x.inner())
}

/// The `Bits<N>` pattern read as an N-bit two's complement number (N <= 128).
pub fn bits_to_i128<const N: usize>(x: Bits<N>) -> i128 {
    let raw = x.to_u128();
    if N == 128 {
        raw as i128
    } else {
        let shift = 128 - N as u32;
        ((raw << shift) as i128) >> shift
    }
}

/// The low N bits of `v` as a `Signed<N>` (wraps, like an N-bit register).
pub fn i128_to_signed<const N: usize>(v: i128) -> Signed<N> {
    signed_cast(u128_to_bits::<N>(v as u128))
}

/// The low N bits of `v` as a `Bits<N>`.
pub fn u128_to_bits<const N: usize>(v: u128) -> Bits<N> {
    if N <= 64 {
        let mask = if N == 64 { u64::MAX } else { (1u64 << N) - 1 };
        Bits::from((v as u64) & mask)
    } else {
        let mut b = [false; N];
        for (i, bit) in b.iter_mut().enumerate() {
            *bit = i < 128 && (v >> i) & 1 == 1;
        }
        Bits::Long(b.into())
    }
}

/// The unsigned value of a `Bits<N>` (N <= 64).
pub fn bits_to_u64<const N: usize>(x: Bits<N>) -> u64 {
    x.to_u64()
}

/// Sign extension (or truncation) of a `Signed<N>` to `Signed<M>`.
///
/// In `#[hdl_gen]` code any function whose name starts with
/// `signed_bit_cast` becomes Verilog `$signed(x)`, which sign-extends when
/// assigned straight to a wider signed signal. rust-hdl's own
/// `signed_bit_cast` recurses forever on the most negative value (Rust side
/// only); this one is exact for every input. Assign its result directly to
/// a `Signal<Local, Signed<M>>`, never inside a larger expression.
pub fn signed_bit_cast_exact<const M: usize, const N: usize>(x: Signed<N>) -> Signed<M> {
    i128_to_signed::<M>(signed_to_i128(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_at_the_extremes() {
        for v in [0i128, 1, -1, 12345, -(1 << 15), (1 << 15) - 1] {
            assert_eq!(signed_to_i128(i128_to_signed::<16>(v)), v);
        }
        for v in [0i128, -1, -(1 << 79), (1 << 79) - 1, 0x1234_5678_9abc_def0] {
            assert_eq!(signed_to_i128(i128_to_signed::<80>(v)), v);
        }
        assert_eq!(signed_to_i128(i128_to_signed::<16>(1 << 15)), -(1 << 15));
        assert_eq!(bits_to_u64(u128_to_bits::<48>(u128::MAX)), (1 << 48) - 1);
    }
}
