//! Typed names: enums whose spelling in job files, on the command line, in results and in reports
//! is written exactly once, in the [`named_enum!`](crate::names::named_enum) declaration.
//!
//! A named enum gets `ALL`, `NAMES`, `name()`, `from_name()`, `Display`, `FromStr` (error:
//! [`UnknownName`]), serde (as its name; an unknown name is a deserialisation error that lists the
//! known ones, so a job file's parser reports it with the file, line and column), clap's
//! `ValueEnum`, and comparison with `&str`.

/// A name that is not one of an enum's names.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {kind} '{given}' (known: {known})")]
pub struct UnknownName {
    /// What was being named ("parameter", "model", ...).
    pub kind: &'static str,
    /// The name given.
    pub given: String,
    /// The known names, comma-separated.
    pub known: String,
}

/// `items`' names joined by `sep` (e.g. `"A, B, k1"`).
pub fn join<T: std::fmt::Display>(items: &[T], sep: &str) -> String {
    items
        .iter()
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(sep)
}

/// Declares a fieldless enum with one name per variant (see the [module docs](crate::names)).
///
/// ```ignore
/// named_enum! {
///     /// Docs of the enum.
///     pub enum Fruit: "fruit" {
///         /// Docs of the variant.
///         Apple => "apple",
///     }
/// }
/// ```
macro_rules! named_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $Name:ident : $kind:literal {
            $( $(#[$vmeta:meta])* $Var:ident => $s:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        $vis enum $Name { $( $(#[$vmeta])* $Var ),+ }

        impl $Name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [$Name] = &[ $( $Name::$Var ),+ ];
            /// Every variant's name, in declaration order.
            pub const NAMES: &'static [&'static str] = &[ $( $s ),+ ];

            /// The name used in files, on the command line and in reports.
            pub fn name(self) -> &'static str {
                match self { $( $Name::$Var => $s ),+ }
            }

            /// The variant called `name`, if any.
            pub fn from_name(name: &str) -> Option<Self> {
                Self::ALL.iter().copied().find(|v| v.name() == name)
            }
        }

        impl std::fmt::Display for $Name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $Name {
            type Err = $crate::names::UnknownName;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                Self::from_name(s).ok_or_else(|| $crate::names::UnknownName {
                    kind: $kind,
                    given: s.to_string(),
                    known: Self::NAMES.join(", "),
                })
            }
        }

        impl serde::Serialize for $Name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $Name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let s = String::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
            }
        }

        impl clap::ValueEnum for $Name {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }
            fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
                Some(clap::builder::PossibleValue::new(self.name()))
            }
        }

        impl PartialEq<&str> for $Name {
            fn eq(&self, other: &&str) -> bool {
                self.name() == *other
            }
        }
    };
}
pub(crate) use named_enum;

#[cfg(test)]
mod tests {
    named_enum! {
        /// A test enum.
        enum Fruit: "fruit" {
            Apple => "apple",
            BloodOrange => "blood_orange",
        }
    }

    #[test]
    fn names_round_trip_through_serde_and_fromstr() {
        for f in Fruit::ALL {
            assert_eq!(f.name().parse::<Fruit>(), Ok(*f));
            let json = serde_json::to_string(f).unwrap();
            assert_eq!(json, format!("\"{}\"", f.name()));
            assert_eq!(serde_json::from_str::<Fruit>(&json).unwrap(), *f);
        }
        assert_eq!(Fruit::BloodOrange, "blood_orange");
    }

    #[test]
    fn unknown_name_lists_the_known_ones() {
        let e = "pear".parse::<Fruit>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown fruit 'pear' (known: apple, blood_orange)"
        );
        let e = serde_json::from_str::<Fruit>("\"pear\"").unwrap_err();
        assert!(e.to_string().contains("unknown fruit 'pear'"), "{e}");
    }
}
