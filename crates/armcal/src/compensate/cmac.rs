//! CMAC, the cerebellar model articulation controller of Albus, as a table-lookup function
//! approximator for nonparametric compensation (book §5.4.2).
//!
//! * Quantisation: each input axis is divided into R resolution units; an input value is
//!   mapped to the nearest unit, `i = nint[(x − lower)/w]` with `w = (upper − lower)/(R − 1)`
//!   (book eq. 5.207 as corrected, `iX = nint[10(x − 2)]` for x ∈ [2, 13.9] in., R = 120).
//!   Inputs outside [lower, upper] use the nearest edge unit.
//! * Q quantising functions (overlapping tilings), each pointing into its own subtable:
//!   along every axis, subtable K = 1, …, Q uses the cell `m = int[(i + Q − K)/Q]` (book
//!   eqs. 5.209–5.210, 0-based), so neighbouring inputs share most of their Q cells
//!   ("generalisation"). Subtable K needs `c_K = int[(R − 1 + Q − K)/Q] + 1` cells per axis
//!   and `c_K^d` words for d inputs; no hashing.
//! * Output: the sum of the Q selected weights, per output (book eq. 5.211, Table 5.8).
//! * Learning (book eq. 5.200): each selected weight is changed by
//!   `Δ = g (desired − output)/Q`, so the output at the taught input moves by the fraction g
//!   of its error.
//!
//! Memory: the book counts `Q (R/Q)^d` words per output (1440 for R = 120, Q = 10, d = 2,
//! against R^d = 14 400 for a one-to-one table; [`book_memory_words`]). The offset
//! subtables of eq. 5.209 need one more cell per axis for K < Q (13 instead of 12 in the
//! book's example), so the exact table ([`Cmac::memory_words`]) is 9·13² + 12² = 1665 words.

use crate::error::{Error, Result};

/// The book's memory count per output (§5.4.2.3): Q subtables of `⌈R/Q⌉^d` words. Q = 1 is
/// the one-to-one table of `R^d` words.
pub fn book_memory_words(resolution: usize, levels: usize, dims: usize) -> usize {
    levels * resolution.div_ceil(levels.max(1)).pow(dims as u32)
}

/// Layout of a CMAC.
#[derive(Clone, Debug, PartialEq)]
pub struct CmacSettings {
    /// Lower input value per axis: the centre of the first resolution unit.
    pub lower: Vec<f64>,
    /// Upper input value per axis: the centre of the last resolution unit.
    pub upper: Vec<f64>,
    /// Resolution units R per axis (the book's example: 120).
    pub resolution: usize,
    /// Number of quantising functions Q, 1 ≤ Q ≤ R − 1 (book §5.4.2.1; the example: 10).
    pub levels: usize,
    /// Number of outputs (one weight table each).
    pub outputs: usize,
}

/// A CMAC function approximator (book §5.4.2): inputs → `outputs` values.
#[derive(Clone, Debug)]
pub struct Cmac {
    lower: Vec<f64>,
    /// Width of one resolution unit per axis.
    width: Vec<f64>,
    resolution: usize,
    levels: usize,
    outputs: usize,
    /// Cells per axis of subtable K (index K − 1).
    cells: Vec<usize>,
    /// First word of subtable K (index K − 1) in `weights` (per output).
    offsets: Vec<usize>,
    /// Words per output, Σ_K c_K^d.
    words: usize,
    /// Weights, word-major: `weights[word * outputs + output]`.
    weights: Vec<f64>,
}

impl Cmac {
    /// A blank CMAC (all weights zero). Errors on an empty or inverted input range,
    /// R < 2, Q outside 1..=R − 1, no outputs, or a table too large to address.
    pub fn new(settings: &CmacSettings) -> Result<Self> {
        let CmacSettings {
            lower,
            upper,
            resolution,
            levels,
            outputs,
        } = settings;
        let (r, q) = (*resolution, *levels);
        let dims = lower.len();
        if dims == 0 || upper.len() != dims {
            return Err(Error::Input(format!(
                "CMAC: {dims} lower and {} upper bounds (need equal, non-zero counts)",
                upper.len()
            )));
        }
        if let Some(i) = (0..dims).find(|&i| !(lower[i].is_finite() && upper[i] > lower[i])) {
            return Err(Error::Input(format!(
                "CMAC: input axis {i} has range [{}, {}]; need finite lower < upper",
                lower[i], upper[i]
            )));
        }
        if r < 2 {
            return Err(Error::Input(format!(
                "CMAC: resolution R = {r}; need at least 2 units per axis"
            )));
        }
        if q == 0 || q >= r {
            return Err(Error::Input(format!(
                "CMAC: Q = {q} quantising functions; need 1 ≤ Q ≤ R − 1 = {} (book §5.4.2.1)",
                r - 1
            )));
        }
        if *outputs == 0 {
            return Err(Error::Input("CMAC: no outputs".to_string()));
        }
        let cells: Vec<usize> = (1..=q).map(|k| (r - 1 + q - k) / q + 1).collect();
        let mut offsets = Vec::with_capacity(q);
        let mut words = 0usize;
        for &c in &cells {
            offsets.push(words);
            let size = c
                .checked_pow(dims as u32)
                .and_then(|s| words.checked_add(s))
                .filter(|w| w.checked_mul(*outputs).is_some());
            words = size.ok_or_else(|| {
                Error::Input(format!(
                    "CMAC: {dims} inputs with R = {r}, Q = {q} need too many table words"
                ))
            })?;
        }
        Ok(Cmac {
            lower: lower.clone(),
            width: (0..dims)
                .map(|i| (upper[i] - lower[i]) / (r - 1) as f64)
                .collect(),
            resolution: r,
            levels: q,
            outputs: *outputs,
            cells,
            offsets,
            words,
            weights: vec![0.0; words * outputs],
        })
    }

    /// Number of inputs d.
    pub fn dims(&self) -> usize {
        self.lower.len()
    }

    /// Number of outputs.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// Number of quantising functions Q.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// Table words per output, `Σ_K c_K^d`.
    pub fn memory_words(&self) -> usize {
        self.words
    }

    /// Resolution unit of `x` along `axis` (nearest unit, clamped to 0..R − 1).
    #[inline]
    fn unit(&self, axis: usize, x: f64) -> usize {
        let u = ((x - self.lower[axis]) / self.width[axis]).round();
        u.clamp(0.0, (self.resolution - 1) as f64) as usize
    }

    /// Word (per output) selected by subtable `k` (0-based, the book's K − 1) for input `x`
    /// (eqs. 5.209–5.210).
    #[inline]
    fn word(&self, k: usize, x: &[f64]) -> usize {
        let c = self.cells[k];
        let shift = self.levels - (k + 1);
        let mut index = 0;
        for axis in (0..x.len()).rev() {
            index = index * c + (self.unit(axis, x[axis]) + shift) / self.levels;
        }
        self.offsets[k] + index
    }

    /// The Q words (per output) selected by input `x`, subtable 1 first.
    pub fn active_words(&self, x: &[f64]) -> Result<Vec<usize>> {
        self.check_input(x)?;
        Ok((0..self.levels).map(|k| self.word(k, x)).collect())
    }

    /// The weight of `word` for `output` (`None` outside the table).
    pub fn weight(&self, word: usize, output: usize) -> Option<f64> {
        (word < self.words && output < self.outputs)
            .then(|| self.weights[word * self.outputs + output])
    }

    /// Sets the weight of `word` for `output` (e.g. to load a taught table).
    pub fn set_weight(&mut self, word: usize, output: usize, value: f64) -> Result<()> {
        if word >= self.words || output >= self.outputs {
            return Err(Error::Input(format!(
                "CMAC: word {word} / output {output} outside the table ({} words, {} outputs)",
                self.words, self.outputs
            )));
        }
        self.weights[word * self.outputs + output] = value;
        Ok(())
    }

    fn check_input(&self, x: &[f64]) -> Result<()> {
        if x.len() != self.dims() {
            return Err(Error::Input(format!(
                "CMAC: input has {} values, the table has {} inputs",
                x.len(),
                self.dims()
            )));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(Error::Input(format!("CMAC: input {i} is {}", x[i])));
        }
        Ok(())
    }

    /// `what` (an output-sized slice of `len` values) must hold one value per output.
    fn check_output_len(&self, what: &str, len: usize) -> Result<()> {
        if len != self.outputs {
            return Err(Error::Input(format!(
                "CMAC: {what} has {len} values, the table has {} outputs",
                self.outputs
            )));
        }
        Ok(())
    }

    /// Output at `x`: the sum of the Q selected weights per output (book eq. 5.211),
    /// written to `out` (`outputs` values). Allocation-free.
    pub fn predict_into(&self, x: &[f64], out: &mut [f64]) -> Result<()> {
        self.check_input(x)?;
        self.check_output_len("output buffer", out.len())?;
        out.fill(0.0);
        for k in 0..self.levels {
            let base = self.word(k, x) * self.outputs;
            for (o, w) in out.iter_mut().zip(&self.weights[base..base + self.outputs]) {
                *o += w;
            }
        }
        Ok(())
    }

    /// Output at `x` (allocates the result; see [`Cmac::predict_into`]).
    pub fn predict(&self, x: &[f64]) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.outputs];
        self.predict_into(x, &mut out)?;
        Ok(out)
    }

    /// One learning experience (book eq. 5.200): every selected weight of each output
    /// changes by `Δ = g (desired − output)/Q`. Returns the squared error norm before the
    /// update. The gain must lie in (0, 2]: the output error at `x` is multiplied by
    /// (1 − g), and the book found no convergence for g > 2 (§5.4.2.3).
    pub fn train(&mut self, x: &[f64], desired: &[f64], gain: f64) -> Result<f64> {
        self.check_input(x)?;
        self.check_output_len("desired output", desired.len())?;
        if !(gain > 0.0 && gain <= 2.0) {
            return Err(Error::Input(format!(
                "CMAC: teaching gain g = {gain}; need 0 < g ≤ 2"
            )));
        }
        if let Some(i) = desired.iter().position(|v| !v.is_finite()) {
            return Err(Error::Input(format!(
                "CMAC: desired output {i} is {}",
                desired[i]
            )));
        }
        let mut squared = 0.0;
        for (j, d) in desired.iter().enumerate() {
            let output: f64 = (0..self.levels)
                .map(|k| self.weights[self.word(k, x) * self.outputs + j])
                .sum();
            let error = d - output;
            squared += error * error;
            let delta = gain * error / self.levels as f64;
            for k in 0..self.levels {
                let w = self.word(k, x) * self.outputs + j;
                self.weights[w] += delta;
            }
        }
        Ok(squared)
    }

    /// `epochs` passes of [`Cmac::train`] over the samples in order. Returns the RMS of the
    /// error norm before each update during the last pass.
    pub fn train_epochs(
        &mut self,
        inputs: &[Vec<f64>],
        desired: &[Vec<f64>],
        gain: f64,
        epochs: usize,
    ) -> Result<f64> {
        if inputs.is_empty() || inputs.len() != desired.len() || epochs == 0 {
            return Err(Error::Input(format!(
                "CMAC: {} inputs, {} desired outputs, {epochs} epochs (need equal, non-zero \
                 counts and at least one epoch)",
                inputs.len(),
                desired.len()
            )));
        }
        let mut squared = 0.0;
        for _ in 0..epochs {
            squared = 0.0;
            for (i, (x, d)) in inputs.iter().zip(desired).enumerate() {
                squared += self
                    .train(x, d, gain)
                    .map_err(|e| Error::Input(format!("sample {i}: {e}")))?;
            }
        }
        Ok((squared / inputs.len() as f64).sqrt())
    }
}
