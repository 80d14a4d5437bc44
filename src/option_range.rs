//! The range check most stages' options share: a finite, non-negative number (a time, a
//! weight, a tolerance).

/// `Err` with the message every stage gives (`"<name> = <value> must be finite and
/// non-negative"`) unless `value` is finite and `≥ 0`; the caller wraps the message in its own
/// error's bad-option variant.
pub(crate) fn non_negative(name: &str, value: f64) -> Result<(), String> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(format!("{name} = {value} must be finite and non-negative"))
    }
}
