//! The firmware's size budget, read from the part's own memory map: `memory.x`'s `FLASH`
//! region is bank 1 of the STM32G474RE (256 KiB in dual-bank mode; bank 2, from
//! 0x0804_0000, holds the record pages and the reset log and never code, so the CPU keeps
//! fetching from bank 1 while a record page is erased: read-while-write). `cargo fw --check`
//! fails above seven eighths of bank 1 (224 KiB: the last eighth stays free for the fixes a
//! board in service needs) and warns above three quarters (192 KiB: time to look at what
//! grew). The static RAM goal stays 32 KiB, the stack's room the rest of the 128 KiB.

/// The flash budget of a bank of `bank_bytes`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// `memory.x`'s `FLASH` length [bytes] (bank 1).
    pub bank: u64,
    /// Above this the check warns [bytes]: three quarters of the bank.
    pub warn_above: u64,
    /// Above this the check fails [bytes]: seven eighths of the bank.
    pub fail_above: u64,
}

/// What the flash use comes to against the budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Within three quarters of the bank.
    Ok,
    /// Above three quarters: a warning.
    Warn,
    /// Above seven eighths: `--check` fails.
    Over,
}

impl Budget {
    /// The budget of a bank of `bank` bytes.
    pub fn of_bank(bank: u64) -> Budget {
        Budget {
            bank,
            warn_above: bank / 4 * 3,
            fail_above: bank / 8 * 7,
        }
    }

    /// The verdict on `used` bytes of flash.
    pub fn verdict(&self, used: u64) -> Verdict {
        if used > self.fail_above {
            Verdict::Over
        } else if used > self.warn_above {
            Verdict::Warn
        } else {
            Verdict::Ok
        }
    }
}

/// The length of the `FLASH` region in the text of a `memory.x` (`LENGTH = 256K`, `512K`,
/// `1M`, `0x40000` or decimal bytes), comments ignored.
pub fn flash_length(memory_x: &str) -> Result<u64, String> {
    let text = strip_comments(memory_x);
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("FLASH"))
        .ok_or("memory.x: no FLASH region")?;
    let length = line
        .split("LENGTH")
        .nth(1)
        .and_then(|rest| rest.split('=').nth(1))
        .map(|v| v.trim().trim_end_matches(',').trim())
        .ok_or_else(|| format!("memory.x: no LENGTH in {line:?}"))?;
    parse_size(length).ok_or_else(|| format!("memory.x: LENGTH {length:?} is not a size"))
}

/// `256K`, `1M`, `0x40000`, `262144` in bytes.
fn parse_size(s: &str) -> Option<u64> {
    let (digits, unit) = match s.chars().last()? {
        'K' | 'k' => (&s[..s.len() - 1], 1024),
        'M' | 'm' => (&s[..s.len() - 1], 1024 * 1024),
        _ => (s, 1),
    };
    let digits = digits.trim();
    let n = match digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        Some(hex) => u64::from_str_radix(hex, 16).ok()?,
        None => digits.parse().ok()?,
    };
    n.checked_mul(unit)
}

/// `text` without its `/* ... */` and `//` comments.
fn strip_comments(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find("/*") {
        out.push_str(&rest[..start]);
        rest = rest[start + 2..]
            .find("*/")
            .map_or("", |end| &rest[start + 2 + end + 2..]);
    }
    out.push_str(rest);
    out.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Bank 2's first address on the STM32G474RE in dual-bank mode: no code from here on.
pub const BANK2_START: u64 = 0x0804_0000;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_is_read_from_the_memory_map() {
        let repo = include_str!("../../../memory.x");
        assert_eq!(flash_length(repo), Ok(256 * 1024));
        let b = Budget::of_bank(256 * 1024);
        assert_eq!((b.warn_above, b.fail_above), (192 * 1024, 224 * 1024));
        assert_eq!(b.verdict(127_848), Verdict::Ok);
        assert_eq!(b.verdict(192 * 1024 + 1), Verdict::Warn);
        assert_eq!(b.verdict(224 * 1024), Verdict::Warn);
        assert_eq!(b.verdict(224 * 1024 + 1), Verdict::Over);
        let other = "MEMORY {\n /* FLASH : LENGTH = 1K */\n  FLASH : ORIGIN = 0x08000000, LENGTH = 0x20000 // 128 KiB\n  RAM : ORIGIN = 0x20000000, LENGTH = 32K\n}";
        assert_eq!(flash_length(other), Ok(128 * 1024));
        assert_eq!(
            flash_length("MEMORY { RAM : ORIGIN = 0, LENGTH = 1K }").map_err(|_| ()),
            Err(())
        );
        assert_eq!(parse_size("1M"), Some(1 << 20));
        assert_eq!(parse_size("262144"), Some(262_144));
        assert_eq!(parse_size("K"), None);
    }
}
