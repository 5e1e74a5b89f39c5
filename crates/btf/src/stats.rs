//! Reconstruction error of a compressed BTF against its measurement.
//!
//! The thesis judges reconstructions by "the length of the 8-bit RGB error vector between the
//! original normtexture and the reconstructed images" (§5.4, Fig. 5.7), i.e. in the 8-bit
//! sRGB units the normtextures are stored in. [`ErrorStats`] reports the RMS per value in
//! those units (both images sRGB-encoded from linear, clamped to [0, 1], not rounded), the
//! PSNR from it (peak 255), the largest error, and the RMS of linear values × 255.
//! Evaluation streams view slot by view slot with bounded memory.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::compress::{for_each_slot_bounded, resolve_workers};
use crate::dataset::{BtfDir, ViewSlot};
use crate::error::{BtfError, Result};
use crate::io::linear_to_srgb;
use crate::model::{BtfPca, LIGHTS};
use crate::sampling::DIRECTIONS;

/// Reconstruction error over a set of images.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ErrorStats {
    /// Images compared.
    pub images: usize,
    /// Values compared (3 per texel).
    pub values: u64,
    /// RMS error per value in 8-bit sRGB units.
    pub rms_srgb8: f64,
    /// 20·log₁₀(255 / rms_srgb8) in dB (∞ for an exact reconstruction).
    pub psnr_db: f64,
    /// Largest absolute error of one value in 8-bit sRGB units.
    pub max_abs_srgb8: f64,
    /// RMS error of linear values × 255.
    pub rms_linear8: f64,
}

/// Running sums of [`ErrorStats`].
#[derive(Clone, Copy, Default)]
struct Acc {
    images: usize,
    values: u64,
    sq_srgb: f64,
    sq_linear: f64,
    max_abs: f64,
}

impl Acc {
    fn add_image(&mut self, original: &[f32], reconstructed: &[[f32; 3]]) {
        let mut sq_srgb = 0.0;
        let mut sq_linear = 0.0;
        for (o, r) in original.chunks_exact(3).zip(reconstructed) {
            for (&a, &b) in o.iter().zip(r) {
                let ds = f64::from(linear_to_srgb(a) - linear_to_srgb(b)) * 255.0;
                let dl = f64::from(a - b) * 255.0;
                sq_srgb += ds * ds;
                sq_linear += dl * dl;
                self.max_abs = self.max_abs.max(ds.abs());
            }
        }
        self.sq_srgb += sq_srgb;
        self.sq_linear += sq_linear;
        self.values += original.len() as u64;
        self.images += 1;
    }

    fn merge(mut self, o: Self) -> Self {
        self.images += o.images;
        self.values += o.values;
        self.sq_srgb += o.sq_srgb;
        self.sq_linear += o.sq_linear;
        self.max_abs = self.max_abs.max(o.max_abs);
        self
    }

    fn finish(self) -> ErrorStats {
        let n = self.values.max(1) as f64;
        let rms = (self.sq_srgb / n).sqrt();
        ErrorStats {
            images: self.images,
            values: self.values,
            rms_srgb8: rms,
            psnr_db: if rms > 0.0 {
                20.0 * (255.0 / rms).log10()
            } else {
                f64::INFINITY
            },
            max_abs_srgb8: self.max_abs,
            rms_linear8: (self.sq_linear / n).sqrt(),
        }
    }
}

impl BtfPca {
    fn check_size(&self, what: &'static str, width: usize, height: usize) -> Result<()> {
        if (width, height) != (self.width, self.height) {
            return Err(BtfError::LengthMismatch {
                what,
                expected: self.width * self.height,
                found: width * height,
                hint: "compare against the BTF the PCA was computed from (same size)",
            });
        }
        Ok(())
    }

    /// Error of every image of one in-memory view slot.
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`] if the slot's size differs from the PCA's.
    pub fn stats_slot(&self, slot: &ViewSlot) -> Result<ErrorStats> {
        self.check_size("BtfPca::stats_slot slot", slot.width(), slot.height())?;
        let mut acc = Acc::default();
        for i in 0..LIGHTS {
            acc.add_image(slot.image(i), &self.image(slot.view(), i));
        }
        Ok(acc.finish())
    }

    /// Error against the measured BTF `dir`: over all 6,561 images (`subset = None`, one view
    /// slot loaded at a time per worker) or over the given (view slot, light) pairs (each image
    /// loaded on its own).
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`] if the folder's size or sampling differs from the PCA's;
    /// [`BtfError::IndexOutOfRange`] for a pair with an index ≥ 81; load errors.
    pub fn stats(&self, dir: &BtfDir, subset: Option<&[(usize, usize)]>) -> Result<ErrorStats> {
        self.stats_with(dir, subset, None)
    }

    /// [`BtfPca::stats`], calling `progress(done, total)` after each view slot compared (all
    /// 6,561 images: 81 slots; a subset: the slots it touches).
    ///
    /// # Errors
    /// As [`BtfPca::stats`].
    pub fn stats_with(
        &self,
        dir: &BtfDir,
        subset: Option<&[(usize, usize)]>,
        progress: Option<&(dyn Fn(usize, usize) + Sync)>,
    ) -> Result<ErrorStats> {
        self.check_size("BtfPca::stats dir", dir.width(), dir.height())?;
        if dir.sampling() != self.sampling {
            return Err(BtfError::InvalidParameter {
                what: "BtfPca::stats",
                name: "dir",
                value: format!("{} (sampling {})", dir.root().display(), dir.sampling()),
                reason: "the folder's sampling differs from the compressed BTF's",
            });
        }
        let workers = resolve_workers(0);
        let done = AtomicUsize::new(0);
        let tick = |total: usize| {
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(p) = progress {
                p(d, total);
            }
        };
        let acc = match subset {
            None => for_each_slot_bounded(workers, DIRECTIONS, |j| {
                let slot = dir.load_view(j)?;
                let mut acc = Acc::default();
                for i in 0..LIGHTS {
                    acc.add_image(slot.image(i), &self.image(j, i));
                }
                tick(DIRECTIONS);
                Ok(acc)
            })?,
            Some(pairs) => {
                let mut by_view: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
                for &(j, i) in pairs {
                    for (what, index) in [("view slot", j), ("light", i)] {
                        if index >= DIRECTIONS {
                            return Err(BtfError::IndexOutOfRange {
                                what,
                                index,
                                len: DIRECTIONS,
                            });
                        }
                    }
                    by_view.entry(j).or_default().push(i);
                }
                let views: Vec<(usize, Vec<usize>)> = by_view.into_iter().collect();
                for_each_slot_bounded(workers, views.len(), |n| {
                    let (j, lights) = &views[n];
                    let mut acc = Acc::default();
                    for &i in lights {
                        let original = dir.load_image(*j, i)?;
                        acc.add_image(&original, &self.image(*j, i));
                    }
                    tick(views.len());
                    Ok(acc)
                })?
            }
        };
        Ok(acc.into_iter().fold(Acc::default(), Acc::merge).finish())
    }
}
