//! What an element is, what class a variant is in, and the planes of a body frame.

use serde::{Deserialize, Serialize};

/// What a balancing element is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElementKind {
    /// A point mass on a body (`m`, offset `r` in the body frame).
    Counterweight,
    /// A zero-free-length spring between two bodies or a body and the ground (`K`, anchors).
    Spring,
}

impl ElementKind {
    /// The machine name used in JSON: `counterweight` or `spring`.
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Counterweight => "counterweight",
            ElementKind::Spring => "spring",
        }
    }
}

/// The paper's three classes of balanced variants: counterweights only, springs only, or both.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    Counterweights,
    Springs,
    Hybrid,
}

impl Class {
    pub const ALL: [Class; 3] = [Class::Counterweights, Class::Springs, Class::Hybrid];

    /// The class of a variant with these element kinds (`None` for no element).
    pub fn of(kinds: impl IntoIterator<Item = ElementKind>) -> Option<Class> {
        let (mut counterweights, mut springs) = (false, false);
        for kind in kinds {
            match kind {
                ElementKind::Counterweight => counterweights = true,
                ElementKind::Spring => springs = true,
            }
        }
        match (counterweights, springs) {
            (true, true) => Some(Class::Hybrid),
            (true, false) => Some(Class::Counterweights),
            (false, true) => Some(Class::Springs),
            (false, false) => None,
        }
    }

    /// The machine name used in results.json and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Class::Counterweights => "counterweights",
            Class::Springs => "springs",
            Class::Hybrid => "hybrid",
        }
    }

    /// The paper's wording, for reports.
    pub fn title(self) -> &'static str {
        match self {
            Class::Counterweights => "Counterweights only",
            Class::Springs => "Springs only",
            Class::Hybrid => "Hybrid",
        }
    }
}

/// A plane of a body frame to which balancing vectors are restricted (the case file's
/// `plane`), and in which the reports give them in polar form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Plane {
    Xy,
    Yz,
    Xz,
}

impl Plane {
    /// Indices of the two body axes spanning the plane, in the order of the polar angle
    /// (`atan2(second, first)`).
    pub fn axes(self) -> [usize; 2] {
        match self {
            Plane::Xy => [0, 1],
            Plane::Yz => [1, 2],
            Plane::Xz => [0, 2],
        }
    }

    /// Index of the body axis normal to the plane.
    pub fn normal(self) -> usize {
        match self {
            Plane::Xy => 2,
            Plane::Yz => 0,
            Plane::Xz => 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The JSON names are the documents' (results.json, `variants --json`, case files).
    #[test]
    fn names_are_the_documents() {
        let json = |v: &dyn erased::Json| v.json();
        assert_eq!(json(&ElementKind::Spring), "\"spring\"");
        assert_eq!(json(&Class::Hybrid), "\"hybrid\"");
        assert_eq!(json(&Plane::Xz), "\"xz\"");
        for k in [ElementKind::Counterweight, ElementKind::Spring] {
            assert_eq!(json(&k), format!("\"{}\"", k.name()));
        }
        for c in Class::ALL {
            assert_eq!(json(&c), format!("\"{}\"", c.name()));
        }
    }

    /// Each plane's axes and normal are the three body axes, once each.
    #[test]
    fn a_planes_axes_and_normal_are_the_three_axes() {
        for p in [Plane::Xy, Plane::Yz, Plane::Xz] {
            let [a, b] = p.axes();
            let mut all = [a, b, p.normal()];
            all.sort();
            assert_eq!(all, [0, 1, 2]);
            assert!(a < b);
        }
    }

    /// The reports' headings are the paper's words for its three classes (Sec. 3).
    #[test]
    fn class_titles_are_the_papers() {
        let titles = Class::ALL.map(Class::title);
        assert_eq!(titles, ["Counterweights only", "Springs only", "Hybrid"]);
    }

    #[test]
    fn a_variants_class_is_what_its_elements_are() {
        use ElementKind::*;
        assert_eq!(
            Class::of([Counterweight, Counterweight]),
            Some(Class::Counterweights)
        );
        assert_eq!(Class::of([Spring]), Some(Class::Springs));
        assert_eq!(Class::of([Spring, Counterweight]), Some(Class::Hybrid));
        assert_eq!(Class::of([]), None);
    }

    mod erased {
        pub trait Json {
            fn json(&self) -> String;
        }
        impl<T: serde::Serialize> Json for T {
            fn json(&self) -> String {
                serde_json::to_string(self).unwrap()
            }
        }
    }
}
