//! Named per-vertex feature columns: the common output of every feature family.

use super::FeatureError;

/// Named per-vertex feature columns of one shape: `N` columns on `d` vertices.
///
/// Columns are paired across shapes **by name** (`ext_dir_007` of shape A with `ext_dir_007`
/// of shape B), so a family must give the same names, in the same order, on every shape of a
/// collection under the same options.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FeatureColumns {
    /// Number of vertices `d`.
    pub vertices: usize,
    /// Column names (length `N`), unique.
    pub names: Vec<String>,
    /// `N × d` values, feature-major: `values[f * d + v]`.
    pub values: Vec<f64>,
}

impl FeatureColumns {
    /// Columns from names and feature-major values, checking the sizes, that names are unique
    /// and that no value is NaN.
    ///
    /// ```
    /// use coseg::features::FeatureColumns;
    /// let c = FeatureColumns::new(2, vec!["a".into()], vec![1.0, 2.0]).unwrap();
    /// assert_eq!(c.column(0), &[1.0, 2.0]);
    /// assert!(FeatureColumns::new(2, vec!["a".into()], vec![1.0]).is_err());
    /// ```
    pub fn new(
        vertices: usize,
        names: Vec<String>,
        values: Vec<f64>,
    ) -> Result<Self, FeatureError> {
        if values.len() != names.len() * vertices {
            return Err(FeatureError::Inconsistent(format!(
                "{} values for {} columns × {vertices} vertices",
                values.len(),
                names.len()
            )));
        }
        let mut sorted: Vec<&String> = names.iter().collect();
        sorted.sort();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(FeatureError::Inconsistent(format!(
                "column name {:?} appears twice",
                w[0]
            )));
        }
        if let Some(i) = values.iter().position(|x| x.is_nan()) {
            return Err(FeatureError::Inconsistent(format!(
                "column {:?} is NaN at vertex {}",
                names[i / vertices.max(1)],
                i % vertices.max(1)
            )));
        }
        Ok(Self {
            vertices,
            names,
            values,
        })
    }

    /// Number of columns `N`.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when there is no column.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Column `f` (length `d`).
    pub fn column(&self, f: usize) -> &[f64] {
        &self.values[f * self.vertices..(f + 1) * self.vertices]
    }
}
