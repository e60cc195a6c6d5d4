//! Host-memory budget: work whose size follows from the input (an extrusion's layers, a bake's
//! textures, a fit's working set, an image) is estimated from counts known before anything is
//! allocated, and refused when the estimate passes the budget. The message names the input, the
//! largest part of the estimate, and the flag that raises the budget.
//!
//! Estimates are sums of `count x bytes` terms over the buffers a piece of work holds at its
//! peak (Vec headers included where a buffer is a Vec of Vecs); they are upper bounds of what the
//! code allocates, checked against measured peaks in the guide's robustness chapter.

use crate::{HairError, Result};

/// Default budget of every tool, MiB: a 4 GiB address space holds any run within it.
pub const DEFAULT_BUDGET_MIB: u64 = 4096;
/// Largest budget a flag may set, MiB (1 TiB).
pub const MAX_BUDGET_MIB: u64 = 1 << 20;

/// Resident memory of a tool before it reads its input (code, Vulkan loader, allocator).
pub const PROCESS_BASELINE: u64 = 64 << 20;

/// Bytes of a `Vec` header (pointer, capacity, length), for Vec-of-Vec estimates.
pub const VEC_HEADER: u64 = 24;

/// The host memory a run may plan to use, and the flag (or field) that sets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    bytes: u64,
    /// What a user changes to raise it: a tool's flag, or the library field.
    setting: &'static str,
}

impl Default for MemoryBudget {
    fn default() -> Self {
        MemoryBudget {
            bytes: DEFAULT_BUDGET_MIB << 20,
            setting: "MemoryBudget",
        }
    }
}

impl MemoryBudget {
    /// A budget of `mib` MiB (1..=[`MAX_BUDGET_MIB`]) raised by `setting` (e.g. a flag name).
    pub fn from_mib(mib: u64, setting: &'static str) -> std::result::Result<Self, String> {
        if !(1..=MAX_BUDGET_MIB).contains(&mib) {
            return Err(format!("{setting} {mib} must be 1..={MAX_BUDGET_MIB} MiB"));
        }
        Ok(MemoryBudget {
            bytes: mib << 20,
            setting,
        })
    }

    /// The budget in bytes.
    pub fn bytes(self) -> u64 {
        self.bytes
    }

    /// Refuse `work` on `source` when `estimate` passes the budget; `smaller` says how to make
    /// the work smaller (a flag, or "a smaller model").
    pub fn check(self, source: &str, work: &str, estimate: &Estimate, smaller: &str) -> Result<()> {
        let total = estimate.clone().with_slack().total();
        if total <= self.bytes {
            return Ok(());
        }
        let (part, part_bytes) = estimate.largest();
        Err(HairError::invalid(
            source,
            format!(
                "{work} needs about {} of memory (largest part: {part}, {}), over the {} budget: {smaller}, or raise {}",
                human_bytes(total),
                human_bytes(part_bytes),
                human_bytes(self.bytes),
                self.setting
            ),
        ))
    }
}

/// An estimate of peak memory as named `count x bytes` parts.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Estimate {
    parts: Vec<(&'static str, u64)>,
}

impl Estimate {
    /// No parts.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add `count` items of `bytes_each` bytes under `name` (saturating: absurd counts stay
    /// absurd instead of wrapping to small).
    pub fn with(mut self, name: &'static str, count: u64, bytes_each: u64) -> Self {
        self.parts.push((name, count.saturating_mul(bytes_each)));
        self
    }

    /// Add every part of `other`.
    pub fn and(mut self, other: Estimate) -> Self {
        self.parts.extend(other.parts);
        self
    }

    /// Bytes of the parts named `name` (0 when there is none).
    pub fn part(&self, name: &str) -> u64 {
        self.parts
            .iter()
            .filter(|p| p.0 == name)
            .fold(0u64, |a, p| a.saturating_add(p.1))
    }

    /// Sum of the parts, bytes (saturating).
    pub fn total(&self) -> u64 {
        self.parts.iter().fold(0u64, |a, p| a.saturating_add(p.1))
    }

    /// The parts plus the process's own memory ([`PROCESS_BASELINE`]) and a quarter for what
    /// the allocator holds beyond the live buffers: what a budget is checked against, and
    /// above every peak measured so far.
    pub fn with_slack(self) -> Self {
        let slack = self.total() / 4;
        self.with("program", PROCESS_BASELINE, 1)
            .with("allocator slack", slack, 1)
    }

    /// The largest part (name, bytes); ("nothing", 0) when empty.
    pub fn largest(&self) -> (&'static str, u64) {
        self.parts
            .iter()
            .copied()
            .max_by_key(|p| p.1)
            .unwrap_or(("nothing", 0))
    }
}

/// `bytes` as "12.3 MiB" / "4.0 GiB".
pub fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= (1u64 << 30) as f64 {
        format!("{:.1} GiB", b / (1u64 << 30) as f64)
    } else {
        format!("{:.1} MiB", b / (1u64 << 20) as f64)
    }
}

/// Value parser of the tools' `--memory-budget-mib` flag.
pub fn parse_budget_flag(s: &str) -> std::result::Result<MemoryBudget, String> {
    let mib: u64 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number of MiB"))?;
    MemoryBudget::from_mib(mib, "--memory-budget-mib")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Survivors of the 2026-12-06 mutation sample: `part` returning 1, and `human_bytes`'s
    /// GiB threshold shifted the wrong way (every size printed in GiB).
    #[test]
    fn parts_sum_by_name_and_sizes_print_in_their_unit() {
        let e = Estimate::new()
            .with("strands", 3, 8)
            .with("textures", 2, 5)
            .with("strands", 1, 6);
        assert_eq!(e.part("strands"), 30);
        assert_eq!(e.part("textures"), 10);
        assert_eq!(e.part("absent"), 0);
        assert_eq!(human_bytes(5 << 20), "5.0 MiB");
        assert_eq!(human_bytes(3 << 30), "3.0 GiB");
    }

    #[test]
    fn estimates_saturate_and_name_their_largest_part() {
        let e = Estimate::new()
            .with("small", 10, 4)
            .with("huge", u64::MAX / 2, 3)
            .with("more", 1 << 40, 1);
        assert_eq!(e.total(), u64::MAX);
        assert_eq!(e.clone().with_slack().total(), u64::MAX);
        assert_eq!(e.largest().0, "huge");
        let err = MemoryBudget::default()
            .check("m.obj", "baking", &e, "lower --extrude")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("m.obj: baking needs about"), "{err}");
        assert!(
            err.contains("largest part: huge,") && err.contains("raise MemoryBudget"),
            "{err}"
        );
        assert!(!err.contains('\n'));
    }

    /// The budget's edges: an estimate whose total with slack is exactly the budget fits (4
    /// MiB of parts + 64 MiB program + 1 MiB slack = 69 MiB), one byte more does not; exactly
    /// 1 GiB prints in GiB; `and` keeps the other estimate's parts; an empty estimate's
    /// largest part is "nothing".
    #[test]
    fn a_budget_is_inclusive_and_estimates_combine() {
        let b = MemoryBudget::from_mib(69, "--memory-budget-mib").unwrap();
        let exact = Estimate::new().with("x", 4 << 20, 1);
        assert_eq!(exact.clone().with_slack().total(), 69 << 20);
        assert!(b.check("f", "w", &exact, "s").is_ok());
        let over = Estimate::new().with("x", (4 << 20) + 4, 1);
        assert!(b.check("f", "w", &over, "s").is_err());
        assert_eq!(human_bytes(1 << 30), "1.0 GiB");
        assert_eq!(human_bytes((1 << 30) - (1 << 20)), "1023.0 MiB");
        let both = Estimate::new()
            .with("a", 2, 3)
            .and(Estimate::new().with("b", 5, 1).with("a", 1, 1));
        assert_eq!((both.part("a"), both.part("b"), both.total()), (7, 5, 12));
        assert_eq!(both.largest(), ("a", 6));
        assert_eq!(Estimate::new().largest(), ("nothing", 0));
        assert_eq!(b.bytes(), 69 << 20);
    }

    #[test]
    fn a_budget_admits_what_fits_and_the_flag_is_bounded() {
        assert_eq!(parse_budget_flag("1").unwrap().bytes(), 1 << 20);
        let b = parse_budget_flag("100").unwrap();
        // 64 MiB program + 28 MiB + a quarter of it = 99 MiB.
        let fits = Estimate::new().with("x", 28 << 20, 1);
        assert!(b.check("f", "w", &fits, "s").is_ok());
        let over = fits.clone().with("y", 1 << 20, 1);
        let err = b.check("f", "w", &over, "s").unwrap_err().to_string();
        assert!(err.contains("raise --memory-budget-mib"), "{err}");
        assert!(parse_budget_flag("0").is_err());
        assert!(parse_budget_flag(&(MAX_BUDGET_MIB + 1).to_string()).is_err());
        assert!(parse_budget_flag("-3").is_err());
        assert!(parse_budget_flag("1e9").is_err());
    }
}
