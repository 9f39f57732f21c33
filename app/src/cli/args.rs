//! Parsers for argument values shared by several subcommands.

use glam::DVec3;
use std::ffi::OsString;

/// Rewrites `OPTION V1 V2 …` as `OPTION=V1 OPTION=V2 …` so that values starting with a minus sign
/// (`--points -1,0,0.5 2,0,0`) reach the option instead of being read as flags.
///
/// A value is any following word that does not start with `-`, or starts with `-` and a digit or
/// `.`; the first other word (the next flag) ends the list. Each `OPTION=V` keeps its place, so the
/// option's values arrive in order.
pub fn attach_values(argv: impl IntoIterator<Item = OsString>, option: &str) -> Vec<OsString> {
    let mut out = Vec::new();
    let mut attaching = false;
    for word in argv {
        let text = word.to_string_lossy();
        if text == option {
            attaching = true;
            out.push(word);
            continue;
        }
        if attaching && is_value(&text) {
            if out.last().is_some_and(|last| last == option) {
                out.pop();
            }
            out.push(OsString::from(format!("{option}={text}")));
            continue;
        }
        attaching = false;
        out.push(word);
    }
    out
}

fn is_value(word: &str) -> bool {
    let mut chars = word.chars();
    match chars.next() {
        Some('-') => chars.next().is_some_and(|c| c.is_ascii_digit() || c == '.'),
        Some(_) => true,
        None => true,
    }
}

/// A finite number, e.g. `--rest 0.5`.
pub fn finite_number(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("'{text}' is not a finite number"))
    }
}

/// A point written `X,Y,Z`, three finite numbers separated by commas, e.g. `-1,0,0.5`.
pub fn point(text: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected X,Y,Z (three numbers separated by commas), got {} part{}",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" }
        ));
    }
    let mut xyz = [0.0; 3];
    for (slot, part) in xyz.iter_mut().zip(&parts) {
        *slot = finite_number(part)?;
    }
    Ok(DVec3::from_array(xyz))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<OsString> {
        s.split(' ').map(OsString::from).collect()
    }

    #[test]
    fn values_after_the_option_are_attached_in_order() {
        assert_eq!(
            attach_values(
                words("tetlab gradient --points -1,0,0.5 2,0,0 --json"),
                "--points"
            ),
            words("tetlab gradient --points=-1,0,0.5 --points=2,0,0 --json")
        );
        // A bare option with no value stays bare, so clap reports the missing value.
        assert_eq!(
            attach_values(words("g --points --json"), "--points"),
            words("g --points --json")
        );
        assert_eq!(
            attach_values(words("g --rest -1"), "--points"),
            words("g --rest -1")
        );
    }

    #[test]
    fn points_accept_negative_and_exponent_notation() {
        assert_eq!(point("-1,0,0.5"), Ok(DVec3::new(-1.0, 0.0, 0.5)));
        assert_eq!(point(" 1e-3, -2E2 ,3"), Ok(DVec3::new(1e-3, -200.0, 3.0)));
    }

    #[test]
    fn malformed_points_are_refused_with_a_reason() {
        assert!(point("1,2").unwrap_err().contains("got 2 parts"));
        assert!(point("1,2,3,4").unwrap_err().contains("got 4 parts"));
        assert!(point("1,x,3").unwrap_err().contains("'x' is not a number"));
        assert!(
            point("1,nan,3")
                .unwrap_err()
                .contains("not a finite number")
        );
        assert!(
            point("inf,0,0")
                .unwrap_err()
                .contains("not a finite number")
        );
        assert!(point("1,,3").unwrap_err().contains("'' is not a number"));
    }
}
