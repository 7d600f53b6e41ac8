//! Typed names, and numbers written for people.
//!
//! Named enums: enums whose spelling in job files, on the command line, in results and in reports
//! is written exactly once, in the [`named_enum!`](crate::names::named_enum) declaration.
//!
//! A named enum gets `ALL`, `NAMES`, `name()`, `from_name()`, `Display`, `FromStr` (error:
//! [`UnknownName`]), serde (as its name; an unknown name is a deserialisation error that lists the
//! known ones, so a job file's parser reports it with the file, line and column) and clap's
//! `ValueEnum`. Code compares variants, never names.
//!
//! [`significant`] and [`quantity`] write a computed number for a person (console lines, error
//! messages): rounded to the digits that mean something, with its unit, never a float's last bits
//! (`1e-4 s`, not `0.00009999999999998899 s`). Files keep full precision.

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

/// `value` rounded to `digits` significant digits (at least 1), written as people write numbers:
/// a plain decimal from 0.001 up to a million without trailing zeros (`140.2`, `5000`, `0.025`),
/// a power of ten outside that range (`1e-4`, `2.5e-10`, `1.2e7`); `NaN` and `inf` as such.
pub fn significant(value: f64, digits: usize) -> String {
    if !value.is_finite() {
        return value.to_string();
    }
    if value == 0.0 {
        return "0".into();
    }
    let digits = digits.max(1);
    // Rounded in scientific form first, so the exponent is the one after rounding (9.9996 → 10).
    let sci = format!("{:.*e}", digits - 1, value);
    let (mantissa, exponent) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (-3..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(&format!("{value:.decimals$}")).to_string()
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

/// `value` to 4 significant digits and its unit: `quantity(9.999999999998899e-5, "s")` is
/// `1e-4 s`, `quantity(887.4612, "Hz")` is `887.5 Hz`.
pub fn quantity(value: f64, unit: &str) -> String {
    format!("{} {unit}", significant(value, 4))
}

/// A decimal without the zeros after its last significant digit (`2.500` → `2.5`, `3.0` → `3`).
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
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
        assert_eq!(Fruit::BloodOrange.name(), "blood_orange");
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

    /// Reference values: the decimal expansion rounded by hand.
    #[test]
    fn numbers_are_written_to_their_significant_digits() {
        use super::{quantity, significant};
        assert_eq!(quantity(0.00009999999999998899, "s"), "1e-4 s");
        assert_eq!(significant(140.22500000000002, 6), "140.225");
        assert_eq!(significant(140.22500000000002, 4), "140.2");
        assert_eq!(significant(5000.00000000055, 6), "5000");
        assert_eq!(significant(10000.0000000011, 6), "10000");
        assert_eq!(significant(9.9996, 4), "10");
        assert_eq!(significant(0.00099996, 4), "0.001");
        assert_eq!(significant(0.025, 4), "0.025");
        assert_eq!(significant(-2.5e-10, 4), "-2.5e-10");
        assert_eq!(significant(1.234567e7, 3), "1.23e7");
        assert_eq!(significant(999_999.0, 6), "999999");
        assert_eq!(significant(999_999.6, 6), "1e6");
        assert_eq!(significant(1.0 / 29.97, 4), "0.03337");
        assert_eq!(significant(0.0, 4), "0");
        assert_eq!(significant(-0.0, 4), "0");
        assert_eq!(significant(f64::NAN, 4), "NaN");
        assert_eq!(significant(f64::NEG_INFINITY, 4), "-inf");
        assert_eq!(significant(7.0, 0), "7");
        assert_eq!(quantity(3.1e-12, "m²/Hz"), "3.1e-12 m²/Hz");
    }
}
