//! [`group_parts`]: merge parts of the same kind (left and right legs, …) into one label.

use super::EvaluateError;
use std::collections::BTreeMap;

/// Parts after grouping: the name of each grouped part and the grouped label of every
/// original part.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartGroups {
    /// Grouped part names; grouped label `g` means `names[g]`.
    pub names: Vec<String>,
    /// Grouped label of every original part label (indexed like the original part names).
    pub of_part: Vec<usize>,
}

impl PartGroups {
    /// Maps per-vertex original labels to grouped labels; errors on a label past the parts.
    pub fn apply(&self, labels: &[i32]) -> Result<Vec<usize>, EvaluateError> {
        labels
            .iter()
            .enumerate()
            .map(|(v, &l)| {
                usize::try_from(l)
                    .ok()
                    .and_then(|l| self.of_part.get(l).copied())
                    .ok_or_else(|| {
                        EvaluateError::BadGroups(format!(
                            "vertex {v} has label {l}, but there are {} parts",
                            self.of_part.len()
                        ))
                    })
            })
            .collect()
    }
}

/// Groups `parts` (label `i` = `parts[i]`) by `groups` (group name → member part names, as in
/// a manifest's `part_groups` or [`crate::generate::Family::part_groups`]). A part in no group
/// keeps its name. Grouped labels follow the order in which parts first appear, so with no
/// groups the labels are unchanged.
///
/// Errors when a group names an unknown part or a part is in two groups.
///
/// ```
/// use coseg::evaluate::group_parts;
/// use std::collections::BTreeMap;
/// let parts: Vec<String> = ["torso", "leg_left", "head", "leg_right"].map(String::from).into();
/// let groups = BTreeMap::from([("leg".to_string(), vec!["leg_left".to_string(), "leg_right".to_string()])]);
/// let g = group_parts(&parts, &groups).unwrap();
/// assert_eq!(g.names, ["torso", "leg", "head"]);
/// assert_eq!(g.of_part, [0, 1, 2, 1]);
/// ```
pub fn group_parts(
    parts: &[String],
    groups: &BTreeMap<String, Vec<String>>,
) -> Result<PartGroups, EvaluateError> {
    let mut group_of: BTreeMap<&str, &str> = BTreeMap::new();
    for (group, members) in groups {
        for m in members {
            if !parts.contains(m) {
                return Err(EvaluateError::BadGroups(format!(
                    "group {group:?} names unknown part {m:?}"
                )));
            }
            if let Some(other) = group_of.insert(m, group) {
                return Err(EvaluateError::BadGroups(format!(
                    "part {m:?} is in groups {other:?} and {group:?}"
                )));
            }
        }
    }
    let mut names: Vec<String> = Vec::new();
    let mut of_part = Vec::with_capacity(parts.len());
    for p in parts {
        let name = group_of.get(p.as_str()).copied().unwrap_or(p);
        let g = match names.iter().position(|n| n == name) {
            Some(g) => g,
            None => {
                names.push(name.to_string());
                names.len() - 1
            }
        };
        of_part.push(g);
    }
    Ok(PartGroups { names, of_part })
}
