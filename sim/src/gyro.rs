//! Two-mode gyroscope model, discretized exactly and stepped once per FPGA clock.
//!
//! # Equations
//!
//! Paper eqs (1)/(3) of Shirazi et al. (TRANSDUCERS 2013), generalized to
//! mismatched modes (one frequency and one Q per mode):
//!
//! ```text
//! x1'' + B1 x1' - 2 lam Omz x2' + w1^2 x1 + d x2' + k x2 = f1(t)
//! x2'' + B2 x2' + 2 lam Omz x1' + w2^2 x2 + d x1' + k x1 = f2(t)
//! Bk = wk / Qk,  wk = 2 pi fk,  k = 2 lam w1 Omq,  d = 2 lam Omd
//! ```
//!
//! `k` is the quadrature (stiffness) coupling, `Omq` = `quadrature_dps` in
//! rad/s: at mode 1's frequency its force on mode 2 is as large as the
//! Coriolis force of a rate `Omq`, 90 deg from it. `d` is the damping
//! coupling, `Omd` = `damping_coupling_dps` in rad/s: its force is as large
//! as the Coriolis force of a rate `Omd` at every frequency, in phase with
//! it, but symmetric (it acts on mode 1 with the same sign as on mode 2,
//! where Coriolis changes sign). Both default to 0 (the paper's model).
//!
//! # Units
//!
//! Positions `x1`, `x2` in m, velocities in m/s, forces per unit mass `f1`, `f2`
//! in N/kg = m/s^2, rate `Omz` in rad/s, frequencies in Hz, the clock in Hz.
//!
//! # Discretization
//!
//! The forces are held constant over each clock period `T = 1/clock_hz`
//! (zero-order hold, like a DAC) and the rate is piecewise constant, so the
//! model is discretized exactly, with no Euler or Runge-Kutta error:
//!
//! ```text
//! exp( [[A, B], [0, 0]] * T ) = [[Phi, Gamma], [0, I]]
//! s[n+1] = Phi s[n] + Gamma [f1[n], f2[n]]^T          s[n] = s(nT)
//! ```
//!
//! `exp` is nalgebra's scaling-and-squaring Pade matrix exponential, evaluated
//! once per rate change (the `Omz = 0` matrices are cached). For conditioning,
//! the state is kept as `[x1, v1/wr, x2, v2/wr]` with `wr = (w1 + w2)/2`, and the
//! input column of the augmented matrix is scaled by `wr^2`, so every entry of
//! the matrix handed to `exp` is of order `w T` (at most about pi) or smaller,
//! instead of mixing 1, 6e7 and 1e-16. A step is then a plain 4x4 plus 4x2
//! multiply on `[f64; 4]` arrays: no allocation, no nalgebra. Steps go in
//! pairs, the second from the state before the first through `Phi^2`
//! ([`GyroModel::step`]), which halves the recursion's latency.
//!
//! # Brownian noise
//!
//! [`GyroModel::with_thermal_noise`] adds the thermomechanical force noise
//! of both modes (mass, temperature, Q; [`crate::noise`]) as the exact
//! per-clock state increment of the continuous process, recomputed with
//! the matrices at each rate change. Off (the default), `step` is the
//! noiseless update, result for result.

use crate::error::ModelError;
use crate::noise::{self, Mat4, StateNoise, ThermalNoise};
use nalgebra::SMatrix;
use std::f64::consts::TAU;

pub use gyrocal_host::device::{CouplingOutOfRange, GyroParams, MAX_COUPLING_DPS};

/// Transition and input matrices of one clock period, as plain arrays,
/// and the transition over two (`Phi^2`, for `GyroModel::step`'s pairs).
#[derive(Clone, Debug, PartialEq)]
struct Discrete {
    phi: [[f64; 4]; 4],
    gamma: [[f64; 2]; 4],
    /// `Phi` and `Phi^2` by columns, the form a step uses.
    phi_by: Columns,
    phi2_by: Columns,
    /// The columns of `Gamma`, and the one column `[g00, g10, g21, g31]`
    /// of its diagonal blocks.
    gamma_by: [[f64; 4]; 2],
    gamma_diagonal: [f64; 4],
}

/// A 4x4 matrix by columns, and its two diagonal 2x2 blocks as two
/// columns, `[m00, m10, m22, m32]` and `[m01, m11, m23, m33]`: a product
/// is then four (or two) lanes wide, each lane the sum a row's dot
/// product takes, in the same order.
#[derive(Clone, Debug, PartialEq)]
struct Columns {
    full: [[f64; 4]; 4],
    diagonal: [[f64; 4]; 2],
}

impl Columns {
    fn new(m: &[[f64; 4]; 4]) -> Self {
        Self {
            full: std::array::from_fn(|j| std::array::from_fn(|i| m[i][j])),
            diagonal: [
                [m[0][0], m[1][0], m[2][2], m[3][2]],
                [m[0][1], m[1][1], m[2][3], m[3][3]],
            ],
        }
    }
}

impl Discrete {
    /// From one period's matrices.
    fn new(phi: [[f64; 4]; 4], gamma: [[f64; 2]; 4]) -> Self {
        let phi2: [[f64; 4]; 4] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|k| phi[i][k] * phi[k][j]).sum())
        });
        Self {
            phi,
            gamma,
            phi_by: Columns::new(&phi),
            phi2_by: Columns::new(&phi2),
            gamma_by: std::array::from_fn(|j| std::array::from_fn(|i| gamma[i][j])),
            gamma_diagonal: [gamma[0][0], gamma[1][0], gamma[2][1], gamma[3][1]],
        }
    }
}

/// The first clock of a pair before this step (its state and input
/// term), if this step is a pair's second.
type Half = Option<([f64; 4], [f64; 4])>;

/// One clock of `GyroModel::step`'s pairs, from the state `s` with the
/// input term `u`: the state after it, and the pair's half.
#[inline(always)]
fn pair_step(
    d: &Discrete,
    coupled: bool,
    s: [f64; 4],
    half: Half,
    u: [f64; 4],
) -> ([f64; 4], Half) {
    match half {
        None => (pair_mid(d, coupled, s, u), Some((s, u))),
        Some((before, first)) => (pair_end(d, coupled, before, first, u), None),
    }
}

/// The state after a pair's first clock from the state `s` with its
/// input term `first`: `first + Phi s`.
#[inline(always)]
fn pair_mid(d: &Discrete, coupled: bool, s: [f64; 4], first: [f64; 4]) -> [f64; 4] {
    let p = times(&d.phi_by, s, coupled);
    std::array::from_fn(|i| first[i] + p[i])
}

/// The state after a whole pair from the state `s` before it, with its
/// clocks' input terms `first` and `u`: `(Phi first + u) + Phi^2 s`, the
/// recursion's latency one product from `s` for two clocks.
#[inline(always)]
fn pair_end(d: &Discrete, coupled: bool, s: [f64; 4], first: [f64; 4], u: [f64; 4]) -> [f64; 4] {
    let carried = times(&d.phi_by, first, coupled);
    let p = times(&d.phi2_by, s, coupled);
    std::array::from_fn(|i| (carried[i] + u[i]) + p[i])
}

/// `m v`, with the products of exact zeros skipped when the modes are
/// decoupled (the off-diagonal blocks are zero). Each lane adds a row's
/// products as `(m0 v0 + m1 v1) + (m2 v2 + m3 v3)`, and the lanes are
/// independent, so a compiler can run them as one vector.
#[inline(always)]
fn times(m: &Columns, v: [f64; 4], coupled: bool) -> [f64; 4] {
    if coupled {
        let c = &m.full;
        std::array::from_fn(|i| {
            (c[0][i] * v[0] + c[1][i] * v[1]) + (c[2][i] * v[2] + c[3][i] * v[3])
        })
    } else {
        let [a, b] = &m.diagonal;
        let (va, vb) = ([v[0], v[0], v[2], v[2]], [v[1], v[1], v[3], v[3]]);
        std::array::from_fn(|i| a[i] * va[i] + b[i] * vb[i])
    }
}

/// The input term of a clock, `Gamma f` (`d`'s, its diagonal blocks
/// alone when the modes are not `coupled`), plus the Brownian increment
/// from `thermal` when on.
#[inline(always)]
fn input_term(
    d: &Discrete,
    coupled: bool,
    thermal: Option<&mut (ThermalNoise, StateNoise)>,
    f1: f64,
    f2: f64,
) -> [f64; 4] {
    let mut u: [f64; 4] = if coupled {
        let [g1, g2] = &d.gamma_by;
        std::array::from_fn(|i| g1[i] * f1 + g2[i] * f2)
    } else {
        let f = [f1, f1, f2, f2];
        std::array::from_fn(|i| d.gamma_diagonal[i] * f[i])
    };
    if let Some((_, source)) = thermal {
        for (u, w) in u.iter_mut().zip(source.sample()) {
            *u += w;
        }
    }
    u
}

/// The gyroscope, stepped once per clock with zero-order-held forces.
///
/// Internal state is scaled (`[x1, v1/wr, x2, v2/wr]`); [`GyroModel::state`]
/// and [`GyroModel::set_state`] use physical units `[x1, v1, x2, v2]`.
#[derive(Clone, Debug)]
pub struct GyroModel {
    params: GyroParams,
    clock_hz: f64,
    /// Reference angular frequency used to scale velocities (rad/s).
    wr: f64,
    omz: f64,
    /// The modes are coupled (a coupling, or `Omz != 0` and lambda != 0):
    /// the full 4x4 step is needed.
    coupled: bool,
    rest: Discrete,
    cur: Discrete,
    s: [f64; 4],
    /// The first clock of a pair (`step`): the state before it and its
    /// input term.
    half: Half,
    /// Brownian noise source and its settings, when on.
    thermal: Option<(ThermalNoise, StateNoise)>,
}

fn check(name: &str, value: f64, ok: bool, allowed: &str) -> Result<(), ModelError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ModelError::parameter(
            name,
            value,
            format!("must be {allowed}"),
        ))
    }
}

impl GyroModel {
    /// Builds the model for a clock of `clock_hz`, at rest (zero state, `Omz = 0`).
    ///
    /// Errors (one line, naming the field) unless `clock_hz` is finite and > 0,
    /// both mode frequencies are finite and in (0, clock_hz/2), both Q are finite
    /// and > 0, the angular gain is finite and both couplings are in range
    /// ([`GyroParams::check_couplings`]).
    pub fn new(params: &GyroParams, clock_hz: f64) -> Result<GyroModel, ModelError> {
        check("clock_hz", clock_hz, clock_hz > 0.0, "finite and > 0 Hz")?;
        let nyq = clock_hz / 2.0;
        let allowed_f = format!("finite and in (0, clock_hz/2 = {nyq} Hz)");
        check(
            "f1_hz",
            params.f1_hz,
            params.f1_hz > 0.0 && params.f1_hz < nyq,
            &allowed_f,
        )?;
        check(
            "f2_hz",
            params.f2_hz,
            params.f2_hz > 0.0 && params.f2_hz < nyq,
            &allowed_f,
        )?;
        check("q1", params.q1, params.q1 > 0.0, "finite and > 0")?;
        check("q2", params.q2, params.q2 > 0.0, "finite and > 0")?;
        check("angular_gain", params.angular_gain, true, "finite")?;
        params.check_couplings()?;
        let w1 = std::f64::consts::TAU * params.f1_hz;
        let w2 = std::f64::consts::TAU * params.f2_hz;
        let wr = 0.5 * (w1 + w2);
        let mut model = GyroModel {
            params: params.clone(),
            clock_hz,
            wr,
            omz: 0.0,
            coupled: params.coupled_at_rest(),
            rest: Discrete::new([[0.0; 4]; 4], [[0.0; 2]; 4]),
            cur: Discrete::new([[0.0; 4]; 4], [[0.0; 2]; 4]),
            s: [0.0; 4],
            half: None,
            thermal: None,
        };
        let mut rest = model.discretize(0.0);
        if !model.coupled {
            // Decoupled modes: the off-diagonal blocks are zero in exact
            // arithmetic (and in nalgebra's Pade evaluation); make that
            // explicit, since step() skips them when uncoupled.
            for (i, j) in [(0, 2), (0, 3), (1, 2), (1, 3)] {
                rest.phi[i][j] = 0.0;
                rest.phi[j][i] = 0.0;
            }
            for i in 0..2 {
                rest.gamma[i][1] = 0.0;
                rest.gamma[i + 2][0] = 0.0;
            }
        }
        model.rest = Discrete::new(rest.phi, rest.gamma);
        model.cur = model.rest.clone();
        Ok(model)
    }

    /// The scaled continuous-time state matrix at rate `omz` (rad/s),
    /// augmented with the input columns (the last two rows are zero).
    #[rustfmt::skip]
    fn augmented(&self, omz: f64) -> SMatrix<f64, 6, 6> {
        let p = &self.params;
        let w1 = std::f64::consts::TAU * p.f1_hz;
        let w2 = std::f64::consts::TAU * p.f2_hz;
        let (b1, b2) = (w1 / p.q1, w2 / p.q2);
        let g = 2.0 * p.angular_gain * omz;
        let wr = self.wr;
        let k = p.quadrature_stiffness() / wr;
        let d = p.damping_coupling();
        // Scaled state s = [x1, u1, x2, u2], u = v/wr; scaled input g_k = f_k/wr^2:
        //   x1' = wr u1,  u1' = -(w1^2/wr) x1 - B1 u1 - (k/wr) x2 + (2 lam Omz - d) u2 + wr g1
        //   x2' = wr u2,  u2' = -(w2^2/wr) x2 - B2 u2 - (k/wr) x1 - (2 lam Omz + d) u1 + wr g2
        SMatrix::<f64, 6, 6>::from_row_slice(&[
            0.0,           wr,     0.0,           0.0,   0.0, 0.0,
            -w1 * w1 / wr, -b1,    -k,            g - d, wr,  0.0,
            0.0,           0.0,    0.0,           wr,    0.0, 0.0,
            -k,            -g - d, -w2 * w2 / wr, -b2,   0.0, wr,
            0.0,           0.0, 0.0,           0.0, 0.0, 0.0,
            0.0,           0.0, 0.0,           0.0, 0.0, 0.0,
        ])
    }

    /// Covariance of the Brownian state increment over one clock at rate
    /// `omz` (scaled state; [`crate::noise`]). The force of mode k, of
    /// two-sided intensity `S_a,k / 2`, enters `uk' = ... + fk / wr`.
    fn thermal_covariance(&self, noise: &ThermalNoise, omz: f64) -> Mat4 {
        let p = &self.params;
        let t = 1.0 / self.clock_hz;
        let a = self.augmented(omz).fixed_view::<4, 4>(0, 0).into_owned() * t;
        let inv_wr2 = 1.0 / (self.wr * self.wr);
        let mut intensity = Mat4::zeros();
        let psd1 = noise.force_psd(p.f1_hz, p.q1);
        intensity[(1, 1)] = psd1 / 2.0 * inv_wr2 * t;
        intensity[(3, 3)] = noise.force_psd(p.f2_hz, p.q2) / 2.0 * inv_wr2 * t;
        // Fluctuation-dissipation: the force noise's covariance is that of
        // the damping matrix [[B1, d], [d, B2]], so the damping coupling
        // correlates the two forces by d / B1 of mode 1's PSD.
        let b1 = TAU * p.f1_hz / p.q1;
        let cross = psd1 * (p.damping_coupling() / b1) / 2.0 * inv_wr2 * t;
        intensity[(1, 3)] = cross;
        intensity[(3, 1)] = cross;
        let mut qd = noise::discrete_covariance(&a, &intensity);
        if !self.coupled_at(omz) {
            // Decoupled modes: independent increments (zero in exact arithmetic).
            for i in 0..2 {
                for j in 2..4 {
                    qd[(i, j)] = 0.0;
                    qd[(j, i)] = 0.0;
                }
            }
        }
        qd
    }

    /// Adds the thermomechanical force noise of `noise` (seeded; its
    /// temperature 0 K leaves the model noiseless). Errors (one line, naming
    /// the field) on a mass or temperature out of range.
    pub fn with_thermal_noise(mut self, noise: &ThermalNoise) -> Result<Self, ModelError> {
        noise.validate()?;
        self.thermal = if noise.is_on() {
            let qd = self.thermal_covariance(noise, self.omz);
            Some((noise.clone(), StateNoise::new(&qd, noise.seed)?))
        } else {
            None
        };
        Ok(self)
    }

    /// The Brownian noise settings, when the noise is on.
    pub fn thermal_noise(&self) -> Option<&ThermalNoise> {
        self.thermal.as_ref().map(|(settings, _)| settings)
    }

    /// Whether the modes are coupled at rate `omz` (rad/s).
    fn coupled_at(&self, omz: f64) -> bool {
        (omz != 0.0 && self.params.angular_gain != 0.0) || self.params.coupled_at_rest()
    }

    /// Exact ZOH discretization at rate `omz` (rad/s).
    fn discretize(&self, omz: f64) -> Discrete {
        let t = 1.0 / self.clock_hz;
        let wr = self.wr;
        let e = (self.augmented(omz) * t).exp();
        let inv_wr2 = 1.0 / (wr * wr);
        let phi = std::array::from_fn(|i| std::array::from_fn(|j| e[(i, j)]));
        // Gamma acts on the physical force f = wr^2 g.
        let gamma = std::array::from_fn(|i| std::array::from_fn(|j| e[(i, 4 + j)] * inv_wr2));
        Discrete::new(phi, gamma)
    }

    /// Sets the (piecewise constant) rotation rate `Omz` (rad/s) that applies from
    /// the next step on; recomputes the transition matrices (cached for 0).
    ///
    /// # Panics
    /// If `omz_rad_s` is not finite.
    pub fn set_rate(&mut self, omz_rad_s: f64) {
        assert!(
            omz_rad_s.is_finite(),
            "set_rate: omz_rad_s = {omz_rad_s}: must be finite"
        );
        if omz_rad_s == self.omz {
            return;
        }
        self.omz = omz_rad_s;
        self.half = None;
        self.coupled = self.coupled_at(omz_rad_s);
        self.cur = if omz_rad_s == 0.0 {
            self.rest.clone()
        } else {
            self.discretize(omz_rad_s)
        };
        if let Some((settings, _)) = &self.thermal {
            let qd = self.thermal_covariance(settings, omz_rad_s);
            if let Some((_, source)) = &mut self.thermal {
                source
                    .set_covariance(&qd)
                    .expect("the covariance at a finite rate is positive definite");
            }
        }
    }

    /// Advances one clock period with the forces per unit mass `f1`, `f2` (N/kg)
    /// held constant over it (zero-order hold).
    ///
    /// At `Omz = 0` without coupling the modes are decoupled and only the two
    /// 2x2 diagonal blocks are used (the others are exactly zero): about 1.3x
    /// faster, same result. A coupling keeps the full 4x4 step at rest.
    /// With thermal noise on, the clock's Brownian increment is added.
    ///
    /// Steps go in pairs, counted from the last change of state or rate:
    /// with `u[n] = Gamma f[n]` (plus the increment),
    ///
    /// ```text
    /// s[n+1] = Phi s[n] + u[n]                    (the pair's first clock)
    /// s[n+2] = Phi^2 s[n] + (Phi u[n] + u[n+1])   (its second)
    /// ```
    ///
    /// The same exact discretization, rounded otherwise: a state leads to
    /// the next-but-one through one product instead of two, so the
    /// recursion's latency, which bounds a co-simulation's clock, is
    /// halved; the bracket and the first clock's state wait on no state.
    /// Every caller steps the same sequence, so the states are the same
    /// whoever plays the clocks.
    #[inline(always)]
    pub fn step(&mut self, f1: f64, f2: f64) {
        let u = self.input(f1, f2);
        (self.s, self.half) = pair_step(&self.cur, self.coupled, self.s, self.half, u);
    }

    /// `forces.len()` clocks of `step`, and `sense` of the state `[x1, v1,
    /// x2, v2]` at each clock's edge, before its step, into `seen`. The
    /// state stays in registers over the run instead of going through
    /// memory at every clock, which would add a store and a load to the
    /// recursion's latency; the loop is compiled for the step's case
    /// (coupled or not, Brownian noise or not) and plays whole pairs, so
    /// no clock tests what the run holds fixed or which half it is.
    #[inline(always)]
    pub fn steps<X>(
        &mut self,
        forces: &[(f64, f64)],
        seen: &mut [X],
        sense: impl FnMut(usize, [f64; 4]) -> X,
    ) {
        match (self.coupled, self.thermal.is_some()) {
            (true, false) => self.steps_as::<true, false, X>(forces, seen, sense),
            (false, false) => self.steps_as::<false, false, X>(forces, seen, sense),
            (true, true) => self.steps_as::<true, true, X>(forces, seen, sense),
            (false, true) => self.steps_as::<false, true, X>(forces, seen, sense),
        }
    }

    /// `steps` with `COUPLED` = `self.coupled` and `THERMAL` =
    /// `self.thermal.is_some()`: a pair begun before the run finished
    /// first, then whole pairs (`pair_step`'s two halves in turn, its
    /// operations in its order), then a pair begun at the run's end.
    #[inline(always)]
    fn steps_as<const COUPLED: bool, const THERMAL: bool, X>(
        &mut self,
        forces: &[(f64, f64)],
        seen: &mut [X],
        mut sense: impl FnMut(usize, [f64; 4]) -> X,
    ) {
        debug_assert_eq!(forces.len(), seen.len());
        debug_assert_eq!((COUPLED, THERMAL), (self.coupled, self.thermal.is_some()));
        let Self {
            cur: d,
            thermal,
            wr,
            s: state,
            half: held,
            ..
        } = self;
        let wr = *wr;
        let mut input = |(f1, f2): (f64, f64)| {
            let thermal = if THERMAL { thermal.as_mut() } else { None };
            input_term(d, COUPLED, thermal, f1, f2)
        };
        let scaled = |s: [f64; 4]| [s[0], s[1] * wr, s[2], s[3] * wr];
        let (mut s, mut half) = (*state, *held);
        let n = forces.len();
        let mut t = 0;
        if half.is_some() && n > 0 {
            seen[0] = sense(0, scaled(s));
            (s, half) = pair_step(d, COUPLED, s, half, input(forces[0]));
            t = 1;
        }
        while t + 2 <= n {
            seen[t] = sense(t, scaled(s));
            let first = input(forces[t]);
            seen[t + 1] = sense(t + 1, scaled(pair_mid(d, COUPLED, s, first)));
            let u = input(forces[t + 1]);
            s = pair_end(d, COUPLED, s, first, u);
            t += 2;
        }
        if t < n {
            seen[t] = sense(t, scaled(s));
            (s, half) = pair_step(d, COUPLED, s, half, input(forces[t]));
        }
        (*state, *held) = (s, half);
    }

    /// `a.steps(forces, seen_a, sense_a)` and `b.steps(forces, seen_b,
    /// sense_b)` (two lanes of a rate table under the same forces), their
    /// whole pairs in one loop where both take the same one (both coupled
    /// or both not, neither with Brownian noise, at the same half of a
    /// pair): one recursion's latency leaves the units idle that the
    /// other's operations then fill. Each model's operations are its own,
    /// in its own order, so each ends where its own `steps` leaves it, bit
    /// for bit; in any other case the two run one after the other.
    #[inline(always)]
    pub fn steps_abreast<X, Y>(
        a: &mut Self,
        b: &mut Self,
        forces: &[(f64, f64)],
        (seen_a, seen_b): (&mut [X], &mut [Y]),
        sense_a: impl FnMut(usize, [f64; 4]) -> X,
        sense_b: impl FnMut(usize, [f64; 4]) -> Y,
    ) {
        let alike = a.coupled == b.coupled
            && a.thermal.is_none()
            && b.thermal.is_none()
            && a.half.is_some() == b.half.is_some();
        match (alike, a.coupled) {
            (true, true) => {
                Self::abreast_as::<true, X, Y>(a, b, forces, (seen_a, seen_b), sense_a, sense_b)
            }
            (true, false) => {
                Self::abreast_as::<false, X, Y>(a, b, forces, (seen_a, seen_b), sense_a, sense_b)
            }
            (false, _) => {
                a.steps(forces, seen_a, sense_a);
                b.steps(forces, seen_b, sense_b);
            }
        }
    }

    /// `steps_abreast` where both take `steps_as::<COUPLED, false>`: the
    /// pair begun before the run finished on each, then whole pairs of
    /// both, then a pair begun at the run's end on each.
    #[inline(always)]
    fn abreast_as<const COUPLED: bool, X, Y>(
        a: &mut Self,
        b: &mut Self,
        forces: &[(f64, f64)],
        (seen_a, seen_b): (&mut [X], &mut [Y]),
        mut sense_a: impl FnMut(usize, [f64; 4]) -> X,
        mut sense_b: impl FnMut(usize, [f64; 4]) -> Y,
    ) {
        let n = forces.len();
        debug_assert!(seen_a.len() == n && seen_b.len() == n);
        let lead = usize::from(a.half.is_some()).min(n);
        let whole = lead + (n - lead) / 2 * 2;
        let (da, db) = (&a.cur, &b.cur);
        let (wa, wb) = (a.wr, b.wr);
        let scaled = |s: [f64; 4], wr: f64| [s[0], s[1] * wr, s[2], s[3] * wr];
        let input = |d: &Discrete, (f1, f2): (f64, f64)| input_term(d, COUPLED, None, f1, f2);
        let (mut sa, mut ha, mut sb, mut hb) = (a.s, a.half, b.s, b.half);
        let mut t = 0;
        while t < n {
            if t >= lead && t < whole {
                // Whole pairs.
                seen_a[t] = sense_a(t, scaled(sa, wa));
                seen_b[t] = sense_b(t, scaled(sb, wb));
                let (fa, fb) = (input(da, forces[t]), input(db, forces[t]));
                let (ma, mb) = (pair_mid(da, COUPLED, sa, fa), pair_mid(db, COUPLED, sb, fb));
                seen_a[t + 1] = sense_a(t + 1, scaled(ma, wa));
                seen_b[t + 1] = sense_b(t + 1, scaled(mb, wb));
                let (ua, ub) = (input(da, forces[t + 1]), input(db, forces[t + 1]));
                sa = pair_end(da, COUPLED, sa, fa, ua);
                sb = pair_end(db, COUPLED, sb, fb, ub);
                t += 2;
                continue;
            }
            // A half pair on each: before the whole pairs or after them.
            seen_a[t] = sense_a(t, scaled(sa, wa));
            (sa, ha) = pair_step(da, COUPLED, sa, ha, input(da, forces[t]));
            seen_b[t] = sense_b(t, scaled(sb, wb));
            (sb, hb) = pair_step(db, COUPLED, sb, hb, input(db, forces[t]));
            t += 1;
        }
        (a.s, a.half, b.s, b.half) = (sa, ha, sb, hb);
    }

    /// The input term of a clock, `Gamma f` plus the Brownian increment
    /// when on.
    #[inline(always)]
    fn input(&mut self, f1: f64, f2: f64) -> [f64; 4] {
        input_term(&self.cur, self.coupled, self.thermal.as_mut(), f1, f2)
    }

    /// Position of mode 1 at the current clock edge (m).
    #[inline]
    pub fn x1(&self) -> f64 {
        self.s[0]
    }

    /// Position of mode 2 at the current clock edge (m).
    #[inline]
    pub fn x2(&self) -> f64 {
        self.s[2]
    }

    /// State `[x1, v1, x2, v2]` at the current clock edge (m, m/s, m, m/s).
    #[inline(always)]
    pub fn state(&self) -> [f64; 4] {
        [
            self.s[0],
            self.s[1] * self.wr,
            self.s[2],
            self.s[3] * self.wr,
        ]
    }

    /// Sets the state `[x1, v1, x2, v2]` (m, m/s, m, m/s).
    pub fn set_state(&mut self, state: [f64; 4]) {
        self.s = [state[0], state[1] / self.wr, state[2], state[3] / self.wr];
        self.half = None;
    }

    /// Zeroes the state (the rate is kept).
    pub fn reset(&mut self) {
        self.s = [0.0; 4];
        self.half = None;
    }

    /// Current rotation rate `Omz` (rad/s).
    pub fn rate(&self) -> f64 {
        self.omz
    }

    /// The parameters the model was built with.
    pub fn params(&self) -> &GyroParams {
        &self.params
    }

    /// The clock frequency (Hz) (one step = one period).
    pub fn clock_hz(&self) -> f64 {
        self.clock_hz
    }
}
