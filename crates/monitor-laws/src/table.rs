//! A magnetising curve from a no-load test: the table a lab writes (line voltage against
//! no-load current at the rated frequency), checked, and turned into Lm(psi_m) for a
//! machine.
//!
//! At no load the slip is nearly zero and the rotor branch carries no current: the phase
//! voltage drives the no-load current through Rs, the stator leakage and Lm. With the
//! current as the reference (the magnetising flux is in phase with it),
//! `V = Rs I + j w (Lls I + psi_m)`, so per phase, peak values:
//! ```text
//!   I = sqrt(2) I0_rms,   V = sqrt(2/3) V_ll_rms,   w = 2 pi f
//!   psi_m = sqrt(V^2 - (Rs I)^2) / w - Lls I,   Lm = psi_m / I
//! ```
//! (the in-phase current of the core loss and the friction is taken as magnetising: a few
//! per cent of the no-load current on a motor of a few kW). Between the table's points
//! the current is interpolated linearly in the flux, below the first point the curve is the
//! line through the origin (the unsaturated Lm), above the last it goes on with the last
//! segment's slope.

use std::path::Path;

/// The header a no-load table has.
pub const HEADER: [&str; 2] = ["v_ll_rms_V", "i0_rms_A"];
/// Fewest points a table must have.
pub const MIN_POINTS: usize = 4;

/// Why a no-load table is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TableError {
    /// The file cannot be read.
    #[error("cannot read the table {path}: {why}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        why: String,
    },
    /// The header is not the table's.
    #[error("the table's header must be v_ll_rms_V,i0_rms_A (line voltage in V, no-load current in A); it is {found}")]
    Header {
        /// The header found.
        found: String,
    },
    /// A column in another unit than the table's.
    #[error("the column {column} is in {unit}; write the table in V and A (v_ll_rms_V,i0_rms_A)")]
    Unit {
        /// The column.
        column: String,
        /// Its unit.
        unit: String,
    },
    /// A cell that is not a positive number.
    #[error("row {row}: '{cell}' is not a positive number")]
    Cell {
        /// The row (1-based, after the header).
        row: usize,
        /// The cell.
        cell: String,
    },
    /// Too few points.
    #[error("{points} points; a no-load curve needs at least {MIN_POINTS}")]
    TooFew {
        /// The points given.
        points: usize,
    },
    /// Voltages not rising from row to row.
    #[error("the voltage does not rise from row {row} to row {next} ({v0} V, then {v1} V): sort the table by voltage, one row per voltage")]
    VoltageOrder {
        /// The row.
        row: usize,
        /// The next row.
        next: usize,
        /// Its voltage [V].
        v0: f64,
        /// The next row's [V].
        v1: f64,
    },
    /// A no-load current that does not rise with the voltage.
    #[error(
        "the no-load current is not monotonic: it falls from {i0} A at {v0} V to {i1} A at {v1} V"
    )]
    NotMonotonic {
        /// The current [A].
        i0: f64,
        /// At this voltage [V].
        v0: f64,
        /// The next current [A].
        i1: f64,
        /// At this voltage [V].
        v1: f64,
    },
    /// The table's voltages do not fit the machine's rated voltage.
    #[error("the table's voltages ({lo}..{hi} V) do not fit the parameter file's rated {rated} V: a no-load test runs from well below to about the rated voltage (units?)")]
    Range {
        /// The lowest voltage [V].
        lo: f64,
        /// The highest [V].
        hi: f64,
        /// The file's [V].
        rated: f64,
    },
    /// With the file's Rs and stator leakage, the flux does not rise with the current.
    #[error("with the parameter file's Rs and stator leakage the table gives a magnetising flux that does not rise with the current (at {v} V): is the table for this motor?")]
    Flux {
        /// Where [V].
        v: f64,
    },
}

/// A no-load test's table: line voltage [V rms] against no-load current [A rms], at the
/// rated frequency, voltages rising.
#[derive(Debug, Clone, PartialEq)]
pub struct NoLoadTable {
    points: Vec<(f64, f64)>,
}

impl NoLoadTable {
    /// A table of `(v_ll_rms_V, i0_rms_A)` points.
    ///
    /// # Errors
    /// [`TableError`]: fewer than [`MIN_POINTS`], values that are not positive, voltages
    /// that do not rise, a current that does not rise with them.
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, TableError> {
        if points.len() < MIN_POINTS {
            return Err(TableError::TooFew {
                points: points.len(),
            });
        }
        for (k, w) in points.windows(2).enumerate() {
            let ((v0, i0), (v1, i1)) = (w[0], w[1]);
            if v1 <= v0 {
                return Err(TableError::VoltageOrder {
                    row: k + 1,
                    next: k + 2,
                    v0,
                    v1,
                });
            }
            if i1 <= i0 {
                return Err(TableError::NotMonotonic { i0, v0, i1, v1 });
            }
        }
        Ok(NoLoadTable { points })
    }

    /// Reads a table file (CSV, header `v_ll_rms_V,i0_rms_A`).
    ///
    /// # Errors
    /// [`TableError`]: the file, its header or units, its cells, or [`NoLoadTable::new`]'s.
    pub fn read(path: &Path) -> Result<Self, TableError> {
        let read = |why: String| TableError::Read {
            path: path.display().to_string(),
            why,
        };
        let mut r = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(path)
            .map_err(|e| read(e.to_string()))?;
        let header: Vec<String> = r
            .headers()
            .map_err(|e| read(e.to_string()))?
            .iter()
            .map(str::to_string)
            .collect();
        check_header(&header)?;
        let mut points = Vec::new();
        for (row, rec) in r.records().enumerate() {
            let rec = rec.map_err(|e| read(e.to_string()))?;
            let cell = |j: usize| -> Result<f64, TableError> {
                let s = rec.get(j).unwrap_or("");
                match s.parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                    _ => Err(TableError::Cell {
                        row: row + 1,
                        cell: s.to_string(),
                    }),
                }
            };
            points.push((cell(0)?, cell(1)?));
        }
        NoLoadTable::new(points)
    }

    /// The points, `(v_ll_rms_V, i0_rms_A)`, voltages rising.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The curve Lm(psi_m) of a machine with stator resistance `rs_ohm`, stator leakage
    /// `lls_h`, rated line voltage `v_rated` [V rms] and frequency `f_hz` (module doc).
    ///
    /// # Errors
    /// [`TableError::Range`] for voltages that do not fit the rated voltage (highest below
    /// half of it, or lowest above twice it), [`TableError::Flux`] where the flux does not
    /// rise with the current.
    pub fn curve(
        &self,
        rs_ohm: f64,
        lls_h: f64,
        v_rated: f64,
        f_hz: f64,
    ) -> Result<MagnetisingCurve, TableError> {
        let (lo, hi) = (self.points[0].0, self.points[self.points.len() - 1].0);
        if hi < 0.5 * v_rated || lo > 2.0 * v_rated {
            return Err(TableError::Range {
                lo,
                hi,
                rated: v_rated,
            });
        }
        let w = 2.0 * std::f64::consts::PI * f_hz;
        let mut psi = Vec::with_capacity(self.points.len());
        let mut im = Vec::with_capacity(self.points.len());
        for &(v_ll, i0) in &self.points {
            let (v, i) = ((2.0f64 / 3.0).sqrt() * v_ll, 2f64.sqrt() * i0);
            let e = (v * v - (rs_ohm * i).powi(2)).max(0.0).sqrt() / w - lls_h * i;
            if e <= 0.0 || psi.last().is_some_and(|p: &f64| e <= *p) {
                return Err(TableError::Flux { v: v_ll });
            }
            psi.push(e);
            im.push(i);
        }
        Ok(MagnetisingCurve { psi, im })
    }
}

/// The header's check: the two columns with their units.
fn check_header(h: &[String]) -> Result<(), TableError> {
    if h.len() == 2 && h[0] == HEADER[0] && h[1] == HEADER[1] {
        return Ok(());
    }
    for (col, (stem, unit)) in h.iter().zip([("v_ll_rms_", "V"), ("i0_rms_", "A")]) {
        if let Some(u) = col.strip_prefix(stem) {
            if u != unit {
                return Err(TableError::Unit {
                    column: col.clone(),
                    unit: u.to_string(),
                });
            }
        }
    }
    Err(TableError::Header { found: h.join(",") })
}

/// A machine's magnetising curve from its no-load table ([`NoLoadTable::curve`]): the flux
/// [Wb, peak] at the magnetising current [A, peak] of each point, both rising.
#[derive(Debug, Clone, PartialEq)]
pub struct MagnetisingCurve {
    psi: Vec<f64>,
    im: Vec<f64>,
}

impl MagnetisingCurve {
    /// The magnetising current [A, peak] at the flux `psi_m` [Wb, peak] (module doc: linear
    /// through the origin below the first point, interpolated, the last slope above).
    pub fn current_a(&self, psi_m: f64) -> f64 {
        let p = psi_m.abs();
        let n = self.psi.len();
        if n == 0 {
            return f64::NAN;
        }
        if p <= self.psi[0] {
            return p * self.im[0] / self.psi[0];
        }
        let k = self.psi.partition_point(|&x| x < p).clamp(1, n - 1);
        let (p0, p1, i0, i1) = (self.psi[k - 1], self.psi[k], self.im[k - 1], self.im[k]);
        i0 + (p - p0) * (i1 - i0) / (p1 - p0)
    }

    /// Lm [H] at the flux `psi_m` [Wb, peak]: `psi_m / i(psi_m)`, the unsaturated value at
    /// zero flux.
    pub fn lm_h(&self, psi_m: f64) -> f64 {
        let p = psi_m.abs();
        match (self.psi.first(), self.im.first()) {
            (Some(&p0), Some(&i0)) if p <= p0 => p0 / i0,
            _ => p / self.current_a(p),
        }
    }

    /// The points as `(im_a, psi_m_wb)`, peak values.
    pub fn points(&self) -> Vec<(f64, f64)> {
        self.im
            .iter()
            .copied()
            .zip(self.psi.iter().copied())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// A table made from a known curve with known Rs and Lls: the conversion gives the
    /// curve back.
    #[test]
    fn the_curve_comes_back_from_its_no_load_table() {
        let (rs, lls, f) = (3.7, 0.01, 50.0);
        let w = 2.0 * std::f64::consts::PI * f;
        // A tanh curve psi(i) = 1.2 tanh(0.3 i / 1.2).
        let psi_of = |i: f64| 1.2 * (0.3 * i / 1.2).tanh();
        let points: Vec<(f64, f64)> = (1..=10)
            .map(|k| {
                let i = 0.6 * k as f64;
                let v = ((rs * i).powi(2) + (w * (lls * i + psi_of(i))).powi(2)).sqrt();
                (v / (2.0f64 / 3.0).sqrt(), i / 2f64.sqrt())
            })
            .collect();
        let c = NoLoadTable::new(points)
            .unwrap()
            .curve(rs, lls, 400.0, f)
            .unwrap();
        for i in [0.6, 1.8, 3.3, 6.0] {
            let p = psi_of(i);
            assert!(
                (c.current_a(p) - i).abs() < 0.03 * i,
                "{i}: {}",
                c.current_a(p)
            );
            assert!((c.lm_h(p) - p / i).abs() < 0.03 * p / i);
        }
        // Unsaturated below the first point, falling Lm above.
        assert_eq!(c.lm_h(0.0), c.lm_h(0.01));
        assert!(c.lm_h(1.1) < 0.8 * c.lm_h(0.1));
    }

    #[test]
    fn bad_tables_are_refused_with_their_reason() {
        let p = |v: &[(f64, f64)]| NoLoadTable::new(v.to_vec());
        assert_eq!(
            p(&[(100.0, 1.0), (200.0, 2.0), (300.0, 3.0)]),
            Err(TableError::TooFew { points: 3 })
        );
        assert!(matches!(
            p(&[(100.0, 1.0), (200.0, 2.0), (300.0, 1.9), (400.0, 5.0)]),
            Err(TableError::NotMonotonic { .. })
        ));
        assert!(matches!(
            p(&[(100.0, 1.0), (300.0, 2.0), (200.0, 3.0), (400.0, 5.0)]),
            Err(TableError::VoltageOrder {
                row: 2,
                next: 3,
                ..
            })
        ));
        let t = p(&[(0.1, 1.0), (0.2, 2.0), (0.3, 3.0), (0.4, 5.0)]).unwrap();
        assert!(matches!(
            t.curve(3.7, 0.0, 400.0, 50.0),
            Err(TableError::Range { .. })
        ));
    }

    #[test]
    fn a_file_with_other_units_is_refused_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let mut f = std::fs::File::create(&path).unwrap();
        writeln!(f, "v_ll_rms_kV,i0_rms_A\n0.1,1\n0.2,2\n0.3,3\n0.4,5").unwrap();
        assert_eq!(
            NoLoadTable::read(&path),
            Err(TableError::Unit {
                column: "v_ll_rms_kV".into(),
                unit: "kV".into()
            })
        );
        std::fs::write(&path, "v_ll_rms_V,i0_rms_A\n100,1\n200,x\n300,3\n400,5\n").unwrap();
        assert_eq!(
            NoLoadTable::read(&path),
            Err(TableError::Cell {
                row: 2,
                cell: "x".into()
            })
        );
        std::fs::write(&path, "v_ll_rms_V,i0_rms_A\n100,1\n200,2\n300,3\n400,5\n").unwrap();
        assert_eq!(NoLoadTable::read(&path).unwrap().points().len(), 4);
    }
}
