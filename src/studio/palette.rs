//! [`Palette`]: the parts of a labelling session, with names and colours.

use super::StudioError;
use crate::render::region_colors;
use serde::{Deserialize, Serialize};

/// One part of the palette.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Part {
    /// The label written to the files (`≥ 0`).
    pub label: i32,
    /// The name shown and written to `parts.json` (may be empty).
    pub name: String,
    /// RGB colour.
    pub color: [u8; 3],
}

/// The parts of a session, ordered by label.
///
/// ```
/// use coseg::studio::Palette;
/// let mut p = Palette::default();
/// let seat = p.add("seat").unwrap();
/// let leg = p.add("leg").unwrap();
/// assert_eq!((seat, leg), (0, 1));
/// p.rename(leg, "front leg").unwrap();
/// p.recolor(leg, [10, 20, 30]).unwrap();
/// assert_eq!(p.get(leg).unwrap().name, "front leg");
/// assert!(p.rename(7, "x").is_err()); // no such part: nothing changes
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Palette {
    parts: Vec<Part>,
}

/// Longest part name accepted, in characters (a name is a label, not a document).
const MAX_NAME: usize = 200;

impl Palette {
    /// The parts, ordered by label.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// The part with `label`, if any.
    pub fn get(&self, label: i32) -> Option<&Part> {
        self.parts.iter().find(|p| p.label == label)
    }

    /// Makes sure `label` (`≥ 0`) is a part (named `name` when new, coloured by
    /// [`region_colors`]); an existing part keeps its name unless it has none.
    pub fn ensure(&mut self, label: i32, name: Option<&str>) {
        if label < 0 {
            return;
        }
        match self.parts.iter_mut().find(|p| p.label == label) {
            Some(p) => {
                if p.name.is_empty()
                    && let Some(n) = name
                {
                    p.name = n.to_string();
                }
            }
            None => {
                self.parts.push(Part {
                    label,
                    name: name.unwrap_or_default().to_string(),
                    color: region_colors(&[label])[0],
                });
                self.parts.sort_by_key(|p| p.label);
            }
        }
    }

    /// Adds a part named `name` with the next free label (one above the largest); returns it.
    pub fn add(&mut self, name: &str) -> Result<i32, StudioError> {
        check_name(name)?;
        let label = self.parts.last().map_or(0, |p| p.label + 1);
        self.ensure(label, Some(name));
        Ok(label)
    }

    /// Renames part `label`.
    pub fn rename(&mut self, label: i32, name: &str) -> Result<(), StudioError> {
        check_name(name)?;
        self.part_mut(label)?.name = name.to_string();
        Ok(())
    }

    /// Gives part `label` the colour `color`.
    pub fn recolor(&mut self, label: i32, color: [u8; 3]) -> Result<(), StudioError> {
        self.part_mut(label)?.color = color;
        Ok(())
    }

    /// The colour of each label (`-1`: grey; a label not in the palette: [`region_colors`]).
    pub fn colors(&self, labels: &[i32]) -> Vec<[u8; 3]> {
        labels
            .iter()
            .map(|&l| match self.get(l) {
                Some(p) => p.color,
                None => region_colors(&[l])[0],
            })
            .collect()
    }

    fn part_mut(&mut self, label: i32) -> Result<&mut Part, StudioError> {
        self.parts
            .iter_mut()
            .find(|p| p.label == label)
            .ok_or_else(|| StudioError::BadRequest(format!("no part with label {label}")))
    }
}

fn check_name(name: &str) -> Result<(), StudioError> {
    if name.chars().count() > MAX_NAME || name.chars().any(char::is_control) {
        return Err(StudioError::BadRequest(format!(
            "a part name has at most {MAX_NAME} characters and no control characters"
        )));
    }
    Ok(())
}
