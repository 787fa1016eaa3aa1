//! The command line's text as a test reads it.

/// The text's verdict line as one line: the line that starts with `verdict: ` and the lines
/// it was wrapped onto (indented by four spaces: the text output wraps at 160 characters),
/// joined by a space; empty where the text has no verdict line.
pub fn verdict_line_of(text: &str) -> String {
    let mut lines = text.lines().skip_while(|l| !l.starts_with("verdict: "));
    let Some(first) = lines.next() else {
        return String::new();
    };
    std::iter::once(first.to_string())
        .chain(
            lines
                .take_while(|l| l.starts_with("    "))
                .map(|l| l.trim_start().to_string()),
        )
        .collect::<Vec<_>>()
        .join(" ")
}

/// The subcommands a `--help` text lists: the first word of each line under `Commands:`
/// indented two spaces (a wrapped description's lines are indented further), `help` left
/// out.
pub fn help_subcommands(text: &str) -> Vec<String> {
    text.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter(|l| !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wrapped_verdict_is_joined_and_the_next_line_left_out() {
        let text = "diagnose x.csv\nverdict: healthy: residuals;\n    winding;\n    rotor\ndata quality: clean\n    not this\n";
        assert_eq!(
            verdict_line_of(text),
            "verdict: healthy: residuals; winding; rotor"
        );
        assert_eq!(verdict_line_of("no verdict here\n"), "");
    }
}
