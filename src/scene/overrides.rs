//! `--set dotted.key=value` overrides, applied to the parsed TOML table before
//! it is checked against the schema, so they reach every scene key and are
//! validated exactly like the file.

use crate::error::SceneError;
use toml::{Table, Value};

/// One parsed `--set` argument.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// The argument as the user wrote it (for messages).
    pub arg: String,
    /// Key path, e.g. `["solver", "shape"]`.
    pub path: Vec<String>,
    pub value: Value,
}

impl Override {
    /// Parses `dotted.key=value`. The value is read as a TOML value
    /// (`0.5`, `[1, 2]`, `"text"`, `true`); anything that is not valid TOML is
    /// taken as a bare string, so `--set solver.shape=ugimp` works unquoted.
    pub fn parse(arg: &str) -> Result<Self, SceneError> {
        let err = |message: &str| SceneError::Override {
            arg: arg.to_string(),
            message: message.to_string(),
        };
        let (key, raw) = arg
            .split_once('=')
            .ok_or_else(|| err("expected dotted.key=value, e.g. solver.shape=ugimp"))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(err("the key before '=' is empty"));
        }
        let path: Vec<String> = key.split('.').map(|s| s.trim().to_string()).collect();
        if path.iter().any(|p| p.is_empty()) {
            return Err(err(
                "the key has an empty part (two dots in a row, or a leading/trailing dot)",
            ));
        }
        let raw = raw.trim();
        if raw.is_empty() {
            return Err(err("the value after '=' is empty"));
        }
        // One value on one line: a newline would start more TOML (a table
        // header, another key) that the parse below would drop unsaid.
        if arg.chars().any(char::is_control) {
            return Err(err(
                "holds a newline or another control character: give one key=value per --set",
            ));
        }
        let value = match format!("v = {raw}").parse::<Table>() {
            Ok(mut t) if t.len() == 1 => t
                .remove("v")
                .expect("parsed table holds the key it was given"),
            Ok(_) => return Err(err("the value is more than one TOML value")),
            Err(_) => Value::String(raw.to_string()),
        };
        Ok(Override {
            arg: arg.to_string(),
            path,
            value,
        })
    }

    /// Writes the value into `table`, creating intermediate tables as needed.
    pub fn apply(&self, table: &mut Table) -> Result<(), SceneError> {
        let (last, parents) = self
            .path
            .split_last()
            .expect("path is non-empty by construction");
        let mut here = table;
        for (depth, part) in parents.iter().enumerate() {
            let entry = here
                .entry(part.clone())
                .or_insert_with(|| Value::Table(Table::new()));
            here = match entry {
                Value::Table(t) => t,
                other => {
                    return Err(SceneError::Override {
                        arg: self.arg.clone(),
                        message: format!(
                            "`{}` is a {}, not a table, so it has no key `{}`",
                            self.path[..=depth].join("."),
                            other.type_str(),
                            self.path[depth + 1]
                        ),
                    });
                }
            };
        }
        here.insert(last.clone(), self.value.clone());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bare_words_become_strings_and_numbers_stay_numbers() {
        let o = Override::parse("solver.shape=ugimp").unwrap();
        assert_eq!(o.path, ["solver", "shape"]);
        assert_eq!(o.value, Value::String("ugimp".into()));
        let o = Override::parse("grid.h=0.0005").unwrap();
        assert_eq!(o.value, Value::Float(0.0005));
        let o = Override::parse("bodies.bar.velocity=[-5, 0]").unwrap();
        assert!(matches!(o.value, Value::Array(ref a) if a.len() == 2));
    }

    #[test]
    fn malformed_arguments_are_rejected() {
        for bad in ["solver.shape", "=3", "a..b=1", "a.b=", ".a=1"] {
            assert!(Override::parse(bad).is_err(), "{bad} should be rejected");
        }
    }

    #[test]
    fn apply_creates_tables_and_refuses_to_descend_into_values() {
        let mut t: Table = "[grid]\nh = 1.0".parse().unwrap();
        Override::parse("gravity.g=[0, -9.81]")
            .unwrap()
            .apply(&mut t)
            .unwrap();
        assert!(t["gravity"]["g"].is_array());
        let e = Override::parse("grid.h.x=1")
            .unwrap()
            .apply(&mut t)
            .unwrap_err();
        assert!(e.to_string().contains("`grid.h` is a float"), "{e}");
    }
}
