use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use std::time::Instant;
fn main() {
    let raw = std::env::args().count() > 1;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut out = vec![0.0f64; 512];
    let mut acc = 0.0;
    let t0 = Instant::now();
    let blocks = 200_000;
    for _ in 0..blocks {
        let mut local = rng.clone();
        if raw {
            for o in out.iter_mut() {
                *o = (local.next_u64() >> 11) as f64;
            }
        } else {
            for o in out.iter_mut() {
                *o = StandardNormal.sample(&mut local);
            }
        }
        rng = local;
        acc += out[17];
    }
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{:.3} ns per sample ({acc})",
        dt * 1e9 / (blocks * 512) as f64
    );
}
