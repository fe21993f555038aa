//! Per-sample numbers in bounded memory, and exact quantiles of them.
//!
//! A sweep's summary wants the nearest-rank median and p95 of every
//! quantity, which needs every value, and its plot wants every sample. A
//! [`Spill`] keeps fixed-width rows of `f64` in memory up to
//! [`RESIDENT_ROWS`] and moves them to an unlinked temporary file beyond
//! that (the operating system's temporary directory; the file has no name,
//! so it cannot be left behind), so that a sweep of 10⁷ samples needs no
//! more memory than one of 10⁵.
//!
//! [`Spill::quantiles`] finds exact nearest-rank values by radix
//! selection: each pass over the rows counts, per wanted rank, the values
//! that share the prefix found so far by their next 16 bits (in an order
//! that sorts like [`f64::total_cmp`]), until few enough remain to be kept
//! and sorted. Five passes at most; one when the rows are few.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom, Write};

/// Rows kept in memory before the first ones go to the file.
pub const RESIDENT_ROWS: usize = 1 << 16;

/// Candidates few enough to be kept and sorted in one pass.
const KEEP: u64 = 1 << 16;

/// Fixed-width rows of `f64`, in memory and then in a temporary file.
#[derive(Debug)]
pub struct Spill {
    width: usize,
    /// The rows not yet on the file, `width` values each.
    resident: Vec<f64>,
    /// Rows already on the file; `None` until the first move.
    file: Option<File>,
    on_file: u64,
}

impl Spill {
    /// No rows yet, of `width` values each.
    pub fn new(width: usize) -> Spill {
        Spill {
            width,
            resident: Vec::new(),
            file: None,
            on_file: 0,
        }
    }

    /// Values per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Rows kept.
    pub fn len(&self) -> u64 {
        self.on_file + (self.resident.len() / self.width.max(1)) as u64
    }

    /// Whether no row was kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Add a row of [`Spill::width`] values.
    pub fn push(&mut self, row: &[f64]) -> std::io::Result<()> {
        debug_assert_eq!(row.len(), self.width);
        self.resident.extend_from_slice(row);
        if self.resident.len() >= RESIDENT_ROWS * self.width.max(1) {
            let file = match &mut self.file {
                Some(file) => file,
                None => self.file.insert(tempfile::tempfile()?),
            };
            let mut bytes = Vec::with_capacity(self.resident.len() * 8);
            for v in &self.resident {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            file.write_all(&bytes)?;
            self.on_file += (self.resident.len() / self.width.max(1)) as u64;
            self.resident.clear();
        }
        Ok(())
    }

    /// Call `f` with every row, in the order they were added.
    pub fn for_each(&self, mut f: impl FnMut(&[f64])) -> std::io::Result<()> {
        let width = self.width.max(1);
        if let Some(file) = &self.file {
            // A second handle shares the first's offset: read from the
            // start, then leave it at the end, where the next row goes.
            let mut handle = file.try_clone()?;
            handle.seek(SeekFrom::Start(0))?;
            let mut reader = BufReader::with_capacity(1 << 20, &mut handle);
            let mut bytes = vec![0u8; 8 * width * 4096];
            let mut row = vec![0.0; width];
            let mut left = self.on_file;
            while left > 0 {
                let rows = left.min(4096) as usize;
                let chunk = &mut bytes[..8 * width * rows];
                reader.read_exact(chunk)?;
                for r in chunk.chunks_exact(8 * width) {
                    for (v, b) in row.iter_mut().zip(r.chunks_exact(8)) {
                        *v = f64::from_le_bytes(b.try_into().expect("8 bytes"));
                    }
                    f(&row);
                }
                left -= rows as u64;
            }
            drop(reader);
            handle.seek(SeekFrom::End(0))?;
        }
        for row in self.resident.chunks_exact(width) {
            f(row);
        }
        Ok(())
    }

    /// The nearest-rank values of each `(column, rank)`, rank 1-based
    /// among that column's finite values, which number `count` for that
    /// column (`counts[column]`). A rank outside 1..=count gives `None`.
    pub fn quantiles(
        &self,
        counts: &[u64],
        wanted: &[(usize, u64)],
    ) -> std::io::Result<Vec<Option<f64>>> {
        let mut targets: Vec<Target> = wanted
            .iter()
            .map(|&(column, rank)| {
                let count = counts.get(column).copied().unwrap_or(0);
                Target {
                    column,
                    rank,
                    prefix: 0,
                    bits: 0,
                    candidates: count,
                    histogram: Vec::new(),
                    kept: Vec::new(),
                    found: (rank == 0 || rank > count).then_some(None),
                }
            })
            .collect();
        while targets.iter().any(|t| t.found.is_none()) {
            for t in targets.iter_mut().filter(|t| t.found.is_none()) {
                if t.candidates > KEEP {
                    t.histogram = vec![0; 1 << 16];
                } else {
                    t.kept = Vec::with_capacity(t.candidates as usize);
                }
            }
            self.for_each(|row| {
                for t in targets.iter_mut().filter(|t| t.found.is_none()) {
                    let value = row[t.column];
                    if !value.is_finite() {
                        continue;
                    }
                    let key = order_key(value);
                    if t.bits > 0 && key >> (64 - t.bits) != t.prefix {
                        continue;
                    }
                    if t.histogram.is_empty() {
                        t.kept.push(key);
                    } else {
                        t.histogram[((key >> (48 - t.bits)) & 0xFFFF) as usize] += 1;
                    }
                }
            })?;
            for t in targets.iter_mut().filter(|t| t.found.is_none()) {
                t.settle();
            }
        }
        Ok(targets.into_iter().map(|t| t.found.flatten()).collect())
    }
}

/// One rank being looked for.
struct Target {
    column: usize,
    /// 1-based, among the values that share `prefix`.
    rank: u64,
    /// The top `bits` bits the value's key is known to have.
    prefix: u64,
    bits: u32,
    /// Values that share the prefix.
    candidates: u64,
    histogram: Vec<u64>,
    kept: Vec<u64>,
    found: Option<Option<f64>>,
}

impl Target {
    /// After a pass: narrow the prefix by the next 16 bits, or pick the
    /// value from those kept.
    fn settle(&mut self) {
        if self.histogram.is_empty() {
            self.kept.sort_unstable();
            self.found = Some(
                self.kept
                    .get((self.rank - 1) as usize)
                    .map(|&k| from_order_key(k)),
            );
            self.kept = Vec::new();
            return;
        }
        let mut below = 0;
        for (digit, &n) in self.histogram.iter().enumerate() {
            if below + n >= self.rank {
                self.rank -= below;
                self.prefix = (self.prefix << 16) | digit as u64;
                self.bits += 16;
                self.candidates = n;
                break;
            }
            below += n;
        }
        self.histogram = Vec::new();
        if self.bits == 64 {
            self.found = Some(Some(from_order_key(self.prefix)));
        }
    }
}

/// A key whose unsigned order is [`f64::total_cmp`]'s order.
fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

fn from_order_key(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nearest rank by sorting, the reference.
    fn sorted_rank(values: &[f64], rank: u64) -> f64 {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        v[(rank - 1) as usize]
    }

    #[test]
    fn order_keys_sort_like_total_cmp() {
        let mut values = vec![-3.5, -0.0, 0.0, 1e-300, -1e300, 2.0, 5e-324, -5e-324];
        let mut by_key = values.clone();
        values.sort_by(f64::total_cmp);
        by_key.sort_by_key(|&x| order_key(x));
        assert_eq!(
            values.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            by_key.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        for x in values {
            assert_eq!(from_order_key(order_key(x)).to_bits(), x.to_bits());
        }
    }

    #[test]
    fn quantiles_on_file_match_sorting() {
        // More rows than stay resident, so most go to the file; values in
        // a narrow band and many repeats, so that selection needs passes
        // of every kind (histogram, narrowing, keeping).
        let n = 3 * RESIDENT_ROWS + 123;
        let mut spill = Spill::new(3);
        let mut columns = vec![Vec::new(); 3];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for i in 0..n {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            let row = [
                1.0 + u * 1e-9,
                f64::from((state % 7) as u32),
                if i % 3 == 0 { f64::NAN } else { -u * 1e3 },
            ];
            for (c, v) in columns.iter_mut().zip(row) {
                c.push(v);
            }
            spill.push(&row).unwrap();
        }
        assert!(spill.on_file > 0 && spill.len() == n as u64);
        let counts: Vec<u64> = columns
            .iter()
            .map(|c| c.iter().filter(|x| x.is_finite()).count() as u64)
            .collect();
        let mut wanted = Vec::new();
        for (c, &count) in counts.iter().enumerate() {
            for rank in [1, count / 2, (count * 95).div_ceil(100), count] {
                wanted.push((c, rank));
            }
        }
        wanted.push((0, counts[0] + 1));
        let found = spill.quantiles(&counts, &wanted).unwrap();
        for (&(c, rank), got) in wanted.iter().zip(&found) {
            if rank > counts[c] {
                assert_eq!(*got, None);
            } else {
                assert_eq!(
                    got.map(f64::to_bits),
                    Some(sorted_rank(&columns[c], rank).to_bits())
                );
            }
        }
        // Rows read back in order, file then memory.
        let mut i = 0;
        spill
            .for_each(|row| {
                assert_eq!(row[1].to_bits(), columns[1][i].to_bits());
                i += 1;
            })
            .unwrap();
        assert_eq!(i, n);
        // and more can be added after reading.
        spill.push(&[0.0, 0.0, 0.0]).unwrap();
        assert_eq!(spill.len(), n as u64 + 1);
    }
}
