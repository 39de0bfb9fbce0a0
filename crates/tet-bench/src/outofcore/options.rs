//! The options of a build under a memory limit and of its jobs: memory
//! sizes (`--memory-limit`, `submit --mem-per-part`), how a scene that
//! does not fit is split (`--planner`) and how the parts are merged
//! (`--merge`).

use clap::ValueEnum;

/// How `build --memory-limit` splits a scene whose prediction exceeds the
/// limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Planner {
    /// The paper's recursive tree, parallel slabs when no tree fits.
    #[default]
    Auto,
    /// Only the paper's recursive tree (perpendicular planes).
    Tree,
    /// Only parallel slabs on the axis of largest variance.
    Slabs,
}

/// How the parts of an out-of-core build are merged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum MergeMode {
    /// Part files merged into the mesh file a part at a time (each part
    /// Hilbert-sorted on its own): the merge holds one part and the seams.
    #[default]
    Stream,
    /// The whole mesh merged in memory and Hilbert-sorted as a whole.
    Memory,
}

/// Parses a memory size: a byte count, or a number with a unit `K`, `M`,
/// `G`, `T` (also `KB`/`KiB`, …, any case), all powers of 1024: `512M`,
/// `1.5G`, `2097152`.
pub fn parse_memory_limit(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_lowercase();
    let scale: f64 = match unit.as_str() {
        "" | "b" => 1.0,
        "k" | "kb" | "kib" => 1024.0,
        "m" | "mb" | "mib" => 1024.0 * 1024.0,
        "g" | "gb" | "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tb" | "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "unknown unit `{unit}` in `{s}`: give bytes or a number with K, M, G or T (powers of 1024), e.g. 512M or 1.5G"
            ));
        }
    };
    let value: f64 = num.parse().map_err(|_| {
        format!("`{s}` is not a memory size: give bytes or a number with K, M, G or T, e.g. 512M or 1.5G")
    })?;
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "memory limit `{s}` must be at least one byte and finite"
        ));
    }
    Ok(bytes.round() as u64)
}

/// Memory per part task.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemPerPart {
    /// From the plan's predictions.
    Auto,
    /// This many bytes.
    Bytes(u64),
}

/// Parses `auto` or a memory size ([`parse_memory_limit`]).
pub fn parse_mem_per_part(s: &str) -> Result<MemPerPart, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        Ok(MemPerPart::Auto)
    } else {
        parse_memory_limit(s).map(MemPerPart::Bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes_parse_with_binary_units() {
        assert_eq!(parse_memory_limit("2097152"), Ok(2_097_152));
        assert_eq!(parse_memory_limit("512M"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("512mb"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("1.5G"), Ok(3 << 29));
        assert_eq!(parse_memory_limit("64 KiB"), Ok(64 << 10));
        for bad in ["", "M", "12X", "-5M", "1.2.3G", "0", "0.1"] {
            let e = parse_memory_limit(bad).unwrap_err();
            assert!(e.contains(bad.trim()), "{bad}: {e}");
        }
    }
}
