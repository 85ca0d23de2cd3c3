//! Analysis of a probe-indentation force trace, after Jasion (2013, *Toward a Physics Based Entrainment
//! Model for Simulation of Helicopter Brownout*, PhD thesis, University of Southampton, Appendix C.4–C.5,
//! following Danby's experiments and Frenning et al.): the mean force F̄ = a yᵖ fitted by least squares
//! after immersion, the fluctuation F′ = F − F̄ windowed (4-term Blackman–Harris) and transformed against
//! depth, its power spectral density normalised by W_p² D_p against the length scale l/D_p, the decay
//! slope γ and the knee where that slope changes. The steps are described in `docs/bed.md`.
//!
//! Everything here works on plain arrays, so the synthetic checks (a sawtooth, a noisy power law) go
//! through exactly the code a probe run uses.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// The mean-force law F̄ = a yᵖ (F in N, y in m, a in N/mᵖ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    pub a: f64,
    pub p: f64,
}

impl PowerLaw {
    /// F̄ at depth `y` \[m\] in N.
    pub fn at(&self, y: f64) -> f64 {
        self.a * y.powf(self.p)
    }
}

/// Range of exponents the fit searches.
const P_RANGE: (f64, f64) = (0.01, 8.0);

/// Least-squares fit of F = a yᵖ to the points (yᵢ > 0, Fᵢ), minimising Σ (Fᵢ − a yᵢᵖ)² in the force
/// itself (not in logarithms, so that forces near zero or negative keep their weight, as in the thesis's
/// curve fit). For a fixed p the best a is Σ F yᵖ / Σ y²ᵖ in closed form, so the fit is a search in p
/// alone: a scan of 800 steps over p ∈ [0.01, 8], refined by golden-section search around the best step
/// to 10⁻¹⁰. Depths are scaled by their largest value inside, so no power under- or overflows. None
/// with fewer than three points, a depth ≤ 0 or a non-finite value.
pub fn fit_power_law(y: &[f64], f: &[f64]) -> Option<PowerLaw> {
    if y.len() != f.len()
        || y.len() < 3
        || y.iter().chain(f).any(|v| !v.is_finite())
        || y.iter().any(|v| *v <= 0.0)
    {
        return None;
    }
    let y_ref = y.iter().copied().fold(0.0, f64::max);
    let s: Vec<f64> = y.iter().map(|v| v / y_ref).collect();
    // Scaled law F = b (y/y_ref)ᵖ; returns (residual sum of squares, b).
    let residual = |p: f64| {
        let (mut fy, mut yy) = (0.0, 0.0);
        for (si, fi) in s.iter().zip(f) {
            let sp = si.powf(p);
            fy += fi * sp;
            yy += sp * sp;
        }
        let b = fy / yy;
        let ss: f64 = s.iter().zip(f).map(|(si, fi)| (fi - b * si.powf(p)).powi(2)).sum();
        (ss, b)
    };
    let steps = 800;
    let h = (P_RANGE.1 - P_RANGE.0) / steps as f64;
    let best = (0..=steps)
        .map(|k| P_RANGE.0 + k as f64 * h)
        .map(|p| (residual(p).0, p))
        .fold((f64::INFINITY, P_RANGE.0), |acc, x| if x.0 < acc.0 { x } else { acc });
    let (mut lo, mut hi) = ((best.1 - h).max(P_RANGE.0), (best.1 + h).min(P_RANGE.1));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (residual(x1).0, residual(x2).0);
    while hi - lo > 1e-10 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = residual(x1).0;
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = residual(x2).0;
        }
    }
    let p = 0.5 * (lo + hi);
    let (_, b) = residual(p);
    let a = b / y_ref.powf(p);
    (a.is_finite() && p.is_finite()).then_some(PowerLaw { a, p })
}

/// The symmetric 4-term Blackman–Harris window of `n` points (Harris 1978, "On the use of windows for
/// harmonic analysis with the discrete Fourier transform", Proc. IEEE 66:51; coefficients 0.35875,
/// 0.48829, 0.14128, 0.01168; the form of Matlab's `blackmanharris`, the thesis's tool).
pub fn blackman_harris(n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![1.0; n];
    }
    let tau = 2.0 * std::f64::consts::PI / (n - 1) as f64;
    (0..n)
        .map(|k| {
            let x = tau * k as f64;
            0.35875 - 0.48829 * x.cos() + 0.14128 * (2.0 * x).cos() - 0.01168 * (3.0 * x).cos()
        })
        .collect()
}

/// A one-sided power spectral density over spatial frequency.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Spectrum {
    /// Spatial frequency κ = k/(N Δy) of each line, k = 1 … N/2 \[1/m\] (the mean, k = 0, left out).
    pub wavenumber: Vec<f64>,
    /// Power spectral density Ψ(κ) \[N² m\] (for a force against depth).
    pub psd: Vec<f64>,
}

/// The one-sided power spectral density of `signal` sampled every `dy` (a depth step in m; or a time
/// step, giving a spectrum over frequency): the signal times the Blackman–Harris window is transformed
/// (rustfft), and Ψ_k = 2 Δy |X_k|² / Σ w² (the Nyquist line, k = N/2, without the 2). With this
/// normalisation the area Σ Ψ_k Δκ is the mean square of the signal, whatever the window (tested on a
/// sine: A²/2). Empty for fewer than 4 samples.
pub fn power_spectrum(signal: &[f64], dy: f64) -> Spectrum {
    let n = signal.len();
    if n < 4 || dy <= 0.0 {
        return Spectrum::default();
    }
    let w = blackman_harris(n);
    let w2: f64 = w.iter().map(|v| v * v).sum();
    let mut buf: Vec<Complex<f64>> = signal.iter().zip(&w).map(|(x, w)| Complex::new(x * w, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let mut out = Spectrum::default();
    for (k, x) in buf.iter().enumerate().take(n / 2 + 1).skip(1) {
        let one_sided = if 2 * k == n { 1.0 } else { 2.0 };
        out.wavenumber.push(k as f64 / (n as f64 * dy));
        out.psd.push(one_sided * dy * x.norm_sqr() / w2);
    }
    out
}

/// The spectrum averaged in logarithmic bins, `per_decade` bins per decade of κ: per non-empty bin the
/// geometric mean of its wavenumbers and the arithmetic mean of its PSD (the mean keeps the power of
/// sharp peaks, so a line spectrum falling as κ^γ gives bin means falling as κ^γ too). Smooths the
/// periodogram, whose single lines scatter by their full size, before slopes are fitted.
pub fn log_binned(s: &Spectrum, per_decade: f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut current: Option<(i64, f64, f64, usize)> = None;
    for (&k, &p) in s.wavenumber.iter().zip(&s.psd) {
        let bin = (k.log10() * per_decade).floor() as i64;
        match &mut current {
            Some((b, lk, sp, n)) if *b == bin => {
                *lk += k.ln();
                *sp += p;
                *n += 1;
            }
            _ => {
                if let Some((_, lk, sp, n)) = current.take() {
                    out.push(((lk / n as f64).exp(), sp / n as f64));
                }
                current = Some((bin, k.ln(), p, 1));
            }
        }
    }
    if let Some((_, lk, sp, n)) = current {
        out.push(((lk / n as f64).exp(), sp / n as f64));
    }
    out
}

/// Least-squares slope of log ψ against log κ over the points with ψ > 0; None for fewer than three.
pub fn log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|(k, p)| *k > 0.0 && *p > 0.0).map(|(k, p)| (k.log10(), p.log10())).collect();
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Where the slope of a log–log spectrum changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knee {
    /// Wavenumber of the break (in the units of the points' κ).
    pub wavenumber: f64,
    /// Slope below the break (smaller κ, larger length scales).
    pub slope_below: f64,
    /// Slope above the break (larger κ, smaller length scales).
    pub slope_above: f64,
}

/// The knee of a log–log spectrum: the continuous two-segment line (one break, at one of the points,
/// with at least three points on each side) that fits log ψ against log κ best in least squares. None
/// with fewer than six usable points.
pub fn knee(points: &[(f64, f64)]) -> Option<Knee> {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|(k, p)| *k > 0.0 && *p > 0.0).map(|(k, p)| (k.log10(), p.log10())).collect();
    if pts.len() < 6 {
        return None;
    }
    let mut best: Option<(f64, Knee)> = None;
    for b in 2..pts.len() - 2 {
        let xb = pts[b].0;
        // y = c + s₁ min(x − x_b, 0) + s₂ max(x − x_b, 0): linear least squares in (c, s₁, s₂).
        let rows: Vec<[f64; 3]> =
            pts.iter().map(|(x, _)| [1.0, (x - xb).min(0.0), (x - xb).max(0.0)]).collect();
        let mut ata = [[0.0; 3]; 3];
        let mut aty = [0.0; 3];
        for (r, (_, y)) in rows.iter().zip(&pts) {
            for i in 0..3 {
                aty[i] += r[i] * y;
                for j in 0..3 {
                    ata[i][j] += r[i] * r[j];
                }
            }
        }
        let Some(c) = solve3(ata, aty) else { continue };
        let sse: f64 =
            rows.iter().zip(&pts).map(|(r, (_, y))| (c[0] + c[1] * r[1] + c[2] * r[2] - y).powi(2)).sum();
        if best.is_none_or(|(s, _)| sse < s) {
            best = Some((sse, Knee { wavenumber: 10f64.powf(xb), slope_below: c[1], slope_above: c[2] }));
        }
    }
    best.map(|(_, k)| k)
}

/// Solves the 3 × 3 system `a x = b` by Cramer's rule; None when it is singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *xk = det(m) / d;
    }
    Some(x)
}

/// Bins per decade of the averaged spectrum the slopes are fitted to.
pub const BINS_PER_DECADE: f64 = 10.0;

/// The decay slope is fitted over length scales below this many particle diameters (the thesis's
/// "l < 0.5 D_p").
pub const GAMMA_MAX_LENGTH_DP: f64 = 0.5;

/// The analysis of one indentation.
#[derive(Clone, Debug)]
pub struct ProbeAnalysis {
    /// The fitted mean force.
    pub fit: PowerLaw,
    /// The same law in particle units: F/W_p = a* (y/D_p)ᵖ.
    pub a_star: f64,
    /// Samples after immersion (fitted and transformed).
    pub samples: usize,
    /// Depth step between samples \[m\].
    pub dy: f64,
    /// The fluctuation's spectrum in SI units.
    pub spectrum: Spectrum,
    /// The normalised spectrum, log-binned: (κ D_p, Ψ/(W_p² D_p)).
    pub binned: Vec<(f64, f64)>,
    /// Length scale of the strongest line, l/D_p.
    pub peak_l_dp: f64,
    /// Slope γ of log Ψ against log κ over l < 0.5 D_p (None when that band holds fewer than three bins).
    pub gamma: Option<f64>,
    /// The knee in that band (None with fewer than six bins).
    pub knee: Option<Knee>,
}

/// Analyses a probe trace: `depth` y \[m\] (equally spaced, increasing) and `force` \[N\] per sample;
/// samples with y ≥ `immersion_depth` \[m\] are used. `d_p` is the mean particle diameter \[m\], `w_p`
/// the mean particle weight \[N\]. An error (a sentence) when fewer than 16 samples are immersed or the
/// fit fails.
pub fn analyse(
    depth: &[f64],
    force: &[f64],
    immersion_depth: f64,
    d_p: f64,
    w_p: f64,
) -> Result<ProbeAnalysis, String> {
    let first = depth.iter().position(|y| *y >= immersion_depth && *y > 0.0).unwrap_or(depth.len());
    let (y, f) = (&depth[first..], &force[first..]);
    if y.len() < 16 {
        return Err(format!(
            "only {} samples after immersion (depth ≥ {immersion_depth:e} m); at least 16 are needed — \
             drive the probe deeper (max_depth_m) or sample faster (sample_hz)",
            y.len()
        ));
    }
    let fit = fit_power_law(y, f).ok_or_else(|| "the power-law fit of the mean force failed".to_string())?;
    let fluctuation: Vec<f64> = y.iter().zip(f).map(|(yi, fi)| fi - fit.at(*yi)).collect();
    let dy = (y[y.len() - 1] - y[0]) / (y.len() - 1) as f64;
    let spectrum = power_spectrum(&fluctuation, dy);
    let norm = 1.0 / (w_p * w_p * d_p);
    let scaled = Spectrum {
        wavenumber: spectrum.wavenumber.iter().map(|k| k * d_p).collect(),
        psd: spectrum.psd.iter().map(|p| p * norm).collect(),
    };
    let peak = scaled
        .psd
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |acc, (i, p)| if *p > acc.1 { (i, *p) } else { acc })
        .0;
    let peak_l_dp = scaled.wavenumber.get(peak).map_or(0.0, |k| 1.0 / k);
    let binned = log_binned(&scaled, BINS_PER_DECADE);
    let band: Vec<(f64, f64)> =
        binned.iter().copied().filter(|(k, _)| *k >= 1.0 / GAMMA_MAX_LENGTH_DP).collect();
    Ok(ProbeAnalysis {
        fit,
        a_star: fit.a * d_p.powf(fit.p) / w_p,
        samples: y.len(),
        dy,
        spectrum,
        binned,
        peak_l_dp,
        gamma: log_slope(&band),
        knee: knee(&band),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::rng::{seeded, RngExt};

    #[test]
    fn power_law_fit_recovers_a_and_p_of_a_noisy_synthetic_trace() {
        // F = a yᵖ with a = 3.2e4 N/m^1.7, p = 1.7 over 0–8 mm (1000 samples), plus Gaussian noise of 2 %
        // of the largest force (seeded). Tolerance: p within 0.02 and a within 5 % (a and p correlate:
        // a change of p by 0.01 moves a by about 5 % at y = 8 mm), and the noise-free trace exactly
        // (1e-8). Both laws are made up; the fit must return what generated the data.
        let (a, p) = (3.2e4, 1.7);
        let y: Vec<f64> = (1..=1000).map(|k| k as f64 * 8e-6).collect();
        let clean: Vec<f64> = y.iter().map(|v| a * v.powf(p)).collect();
        let exact = fit_power_law(&y, &clean).unwrap();
        assert!((exact.p - p).abs() < 1e-8 && (exact.a / a - 1.0).abs() < 1e-8, "{exact:?}");
        let mut rng = seeded(7, 0);
        let top = clean[clean.len() - 1];
        let noisy: Vec<f64> = clean
            .iter()
            .map(|f| {
                let g: f64 = rng.sample(rand_distr::StandardNormal);
                f + 0.02 * top * g
            })
            .collect();
        let fit = fit_power_law(&y, &noisy).unwrap();
        assert!((fit.p - p).abs() < 0.02, "p = {}", fit.p);
        assert!((fit.a / a - 1.0).abs() < 0.05, "a = {}", fit.a);
        // A sub-linear law (the thesis's frictionless beds, p ≈ 0.7).
        let soft: Vec<f64> = y.iter().map(|v| 5.0 * v.powf(0.7)).collect();
        let fit = fit_power_law(&y, &soft).unwrap();
        assert!((fit.p - 0.7).abs() < 1e-8 && (fit.a / 5.0 - 1.0).abs() < 1e-7, "{fit:?}");
        assert_eq!(fit_power_law(&y[..2], &soft[..2]), None, "two points are too few");
    }

    #[test]
    fn the_spectrum_of_a_sine_holds_its_mean_square_at_its_frequency() {
        // A sine of amplitude 2 N at 40 cycles per metre, sampled every 0.5 mm over 1 m: the PSD peaks on
        // the 40 /m line and its area is the mean square A²/2 = 2 N² (Parseval; 1 % for the window's
        // leakage beyond the record).
        let dy = 5e-4;
        let x: Vec<f64> =
            (0..2000).map(|k| 2.0 * (2.0 * std::f64::consts::PI * 40.0 * k as f64 * dy).sin()).collect();
        let s = power_spectrum(&x, dy);
        let dk = s.wavenumber[0];
        let area: f64 = s.psd.iter().sum::<f64>() * dk;
        assert!((area / 2.0 - 1.0).abs() < 0.01, "area {area}");
        let peak = s.psd.iter().enumerate().fold((0, 0.0), |a, (i, p)| if *p > a.1 { (i, *p) } else { a }).0;
        assert!((s.wavenumber[peak] - 40.0).abs() < 1e-9);
    }

    /// A sawtooth of frequency `f0` (rising ramps from −1 to 1), sampled at `fs` for `seconds`.
    fn sawtooth(f0: f64, fs: f64, seconds: f64) -> Vec<f64> {
        let n = (fs * seconds).round() as usize;
        (0..n).map(|k| 2.0 * (k as f64 * f0 / fs).fract() - 1.0).collect()
    }

    #[test]
    fn a_10_hz_sawtooth_peaks_at_10_hz_and_its_harmonics_fall_as_f_to_the_minus_2() {
        // Jasion (2013), Appendix D: a 10 Hz sawtooth through a Blackman–Harris window and an FFT shows
        // its principal peak at 10 Hz and harmonics at integer multiples whose power falls with slope
        // γ = −2 (the Fourier amplitudes of a sawtooth are 2/(π n)). Records of 10 s, so that every
        // harmonic sits on a line.
        //
        // At the experiment's 500 Hz (P = 50 samples per period) the sampled ramp's harmonics have the
        // powers of the discrete sawtooth, ∝ 1/sin²(π n/P) (its jump is aliased), which bends the slope
        // of the first 20 harmonics to −1.82; the peak is on the 10 Hz line and each harmonic's power
        // matches sin²(π/P)/sin²(π n/P) of the first within 1 %. At 5 kHz (P = 500) the first 20
        // harmonics fall with slope −2 within 0.01, and the probe analysis' γ over the log-binned
        // spectrum of a band-limited sawtooth (what a probe run reports) is −2 within 0.1.
        let harmonics = |fs: f64| {
            let x = sawtooth(10.0, fs, 10.0);
            let s = power_spectrum(&x, 1.0 / fs);
            let peak =
                s.psd.iter().enumerate().fold((0, 0.0), |a, (i, p)| if *p > a.1 { (i, *p) } else { a }).0;
            assert!((s.wavenumber[peak] - 10.0).abs() < 1e-9, "peak at {} Hz", s.wavenumber[peak]);
            let line = |f: f64| (f / s.wavenumber[0]).round() as usize - 1;
            (1..=20).map(|n| (10.0 * n as f64, s.psd[line(10.0 * n as f64)])).collect::<Vec<_>>()
        };
        let h = harmonics(500.0);
        let pi = std::f64::consts::PI;
        for (n, (_, p)) in h.iter().enumerate().map(|(i, x)| (i + 1, x)) {
            let expect = (pi / 50.0).sin().powi(2) / (pi * n as f64 / 50.0).sin().powi(2);
            assert!((p / h[0].1 / expect - 1.0).abs() < 0.01, "harmonic {n}: {} vs {expect}", p / h[0].1);
        }
        let slope = log_slope(&harmonics(5000.0)).unwrap();
        assert!((slope + 2.0).abs() < 0.01, "harmonic slope {slope}");
        // The probe analysis: time stands for depth. Its γ is fitted to bin means, which follow the
        // harmonics' f^−2 where a bin holds several of them; D_p = 0.01 s puts the band l < 0.5 D_p at
        // frequencies above 200 Hz (bins at least 46 Hz wide over harmonics 10 Hz apart). The sawtooth is
        // summed from its Fourier series up to the Nyquist frequency (2/(π n) sin(2π n f₀ t)), so that
        // the aliased jump of a sampled ramp does not flatten the top of the band. The trace is a mean
        // law plus the sawtooth, so the fit and the detrending run too.
        let fs = 5000.0;
        let t: Vec<f64> = (1..=50_000).map(|k| k as f64 / fs).collect();
        let saw = |t: f64| -> f64 {
            (1..250).map(|n| -2.0 / (pi * n as f64) * (2.0 * pi * 10.0 * n as f64 * t).sin()).sum()
        };
        let force: Vec<f64> = t.iter().map(|t| 50.0 * t.powf(1.5) + saw(*t)).collect();
        let r = analyse(&t, &force, 0.0, 0.01, 1.0).unwrap();
        assert!((r.fit.p - 1.5).abs() < 0.01, "p = {}", r.fit.p);
        let gamma = r.gamma.unwrap();
        assert!((gamma + 2.0).abs() < 0.1, "γ = {gamma}");
        assert!((r.peak_l_dp - 10.0).abs() < 1e-9, "principal length 0.1 s = 10 D_p: {}", r.peak_l_dp);
    }

    #[test]
    fn a_knee_is_found_where_the_slope_changes() {
        // A synthetic spectrum ψ = κ^−2 up to κ = 30, flat beyond (a noise floor): the knee at 30 (within
        // the spacing of the points, a factor 10^0.1) and the two slopes within 0.1 (the true break lies
        // between two points, the fitted one on a point).
        let pts: Vec<(f64, f64)> = (0..30)
            .map(|i| 10f64.powf(i as f64 * 0.1))
            .map(|k| (k, if k <= 30.0 { k.powi(-2) } else { 30f64.powi(-2) }))
            .collect();
        let k = knee(&pts).unwrap();
        assert!((k.wavenumber / 30.0).log10().abs() <= 0.1, "knee at {}", k.wavenumber);
        assert!((k.slope_below + 2.0).abs() < 0.1 && k.slope_above.abs() < 0.1, "{k:?}");
    }
}
