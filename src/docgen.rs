//! Regenerated sections of the markdown docs: the text between
//! `<!-- BEGIN name -->` and `<!-- END name -->` is replaced by what a
//! command measured, so figures in docs/ are never typed by hand.

use crate::error::Result;
use std::path::Path;

/// Replaces section `name` of `file` with `body` (creating the markers at the
/// end of the file if the section does not exist yet).
pub fn replace_section(file: &Path, name: &str, body: &str) -> Result<()> {
    let text = std::fs::read_to_string(file).unwrap_or_default();
    let begin = format!("<!-- BEGIN {name} -->");
    let end = format!("<!-- END {name} -->");
    let block = format!("{begin}\n{}\n{end}", body.trim_end());
    let new = match (text.find(&begin), text.find(&end)) {
        (Some(b), Some(e)) if e > b => format!("{}{}{}", &text[..b], block, &text[e + end.len()..]),
        _ => format!(
            "{}{}{block}\n",
            text,
            if text.is_empty() || text.ends_with('\n') {
                ""
            } else {
                "\n"
            }
        ),
    };
    crate::output::write_atomic(file, new.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_replaced_in_place_or_appended() {
        let f = std::env::temp_dir().join(format!("lme-mpm-docgen-{}.md", std::process::id()));
        std::fs::write(&f, "# Title\n<!-- BEGIN a -->\nold\n<!-- END a -->\ntail\n").unwrap();
        replace_section(&f, "a", "new 1\nnew 2").unwrap();
        replace_section(&f, "b", "bee").unwrap();
        let t = std::fs::read_to_string(&f).unwrap();
        assert_eq!(
            t,
            "# Title\n<!-- BEGIN a -->\nnew 1\nnew 2\n<!-- END a -->\ntail\n<!-- BEGIN b -->\nbee\n<!-- END b -->\n"
        );
        let _ = std::fs::remove_file(f);
    }
}
