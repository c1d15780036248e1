//! `robot_description` (and `robot_description_semantic`) as the node decodes it: a
//! `std_msgs/msg/String` whose size bound is checked before the text is copied out of the sample,
//! and the line a refused one is reported with.

use crate::limits::MAX_DESCRIPTION_BYTES;
use serde::{Deserialize, Serialize};

/// The line a refused description is logged and diagnosed with: the topic once, then why. The
/// error names its source (`/robot_description topic: ...`) when it comes from the text itself;
/// that prefix is dropped, as the line already starts with the topic.
pub(super) fn refusal_line(topic: &str, source: &str, what_stays: &str, error: &str) -> String {
    let error = error.replace('\n', " ");
    let reason = error.strip_prefix(source).and_then(|r| r.strip_prefix(": ")).unwrap_or(&error);
    format!("{topic} rejected, {what_stays}: {reason}")
}

/// `std_msgs/msg/String` on `robot_description`, its length checked before the text is copied out
/// of the DDS sample: text past [`MAX_DESCRIPTION_BYTES`] comes back as
/// [`DescriptionMsg::TooLarge`] (to be refused with the bound in the error), so a 50 MB
/// description costs the node its sample, never a second copy.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum DescriptionMsg {
    /// URDF text within the bound.
    Text(String),
    /// Text of this many bytes, past the bound.
    TooLarge(usize),
}

impl Serialize for DescriptionMsg {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeStruct};
        let mut s = serializer.serialize_struct("String", 1)?;
        match self {
            DescriptionMsg::Text(text) => s.serialize_field("data", text)?,
            DescriptionMsg::TooLarge(n) => return Err(S::Error::custom(format!("a description of {n} bytes was not kept, so cannot be sent"))),
        }
        s.end()
    }
}

/// The `data` field: checked on the borrowed text, copied only when within the bound.
struct BoundedText;

impl BoundedText {
    fn of(text: &str) -> DescriptionMsg {
        if text.len() as u64 > MAX_DESCRIPTION_BYTES {
            DescriptionMsg::TooLarge(text.len())
        } else {
            DescriptionMsg::Text(text.to_owned())
        }
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for BoundedText {
    type Value = DescriptionMsg;
    fn deserialize<D: serde::Deserializer<'de>>(self, deserializer: D) -> Result<DescriptionMsg, D::Error> {
        deserializer.deserialize_str(self)
    }
}

impl serde::de::Visitor<'_> for BoundedText {
    type Value = DescriptionMsg;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("URDF text")
    }
    fn visit_str<E: serde::de::Error>(self, text: &str) -> Result<DescriptionMsg, E> {
        Ok(Self::of(text))
    }
}

impl<'de> Deserialize<'de> for DescriptionMsg {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<DescriptionMsg, D::Error> {
        struct Fields;
        impl<'de> serde::de::Visitor<'de> for Fields {
            type Value = DescriptionMsg;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a std_msgs/msg/String")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<DescriptionMsg, A::Error> {
                seq.next_element_seed(BoundedText)?.ok_or_else(|| serde::de::Error::invalid_length(0, &self))
            }
        }
        deserializer.deserialize_struct("String", &["data"], Fields)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::StringMsg;
    use byteorder::LittleEndian;

    fn cdr(text: &str) -> Vec<u8> {
        cdr_encoding::to_vec::<_, LittleEndian>(&StringMsg { data: text.to_owned() }).unwrap()
    }

    #[test]
    fn a_description_decodes_as_a_string_does() {
        let (m, _) = cdr_encoding::from_bytes::<DescriptionMsg, LittleEndian>(&cdr("<robot name='r'/>")).unwrap();
        assert_eq!(m, DescriptionMsg::Text("<robot name='r'/>".into()));
        let back = cdr_encoding::to_vec::<_, LittleEndian>(&m).unwrap();
        assert_eq!(back, cdr("<robot name='r'/>"));
    }

    #[test]
    fn a_description_past_the_bound_is_not_copied() {
        let big = " ".repeat(MAX_DESCRIPTION_BYTES as usize + 1);
        let (m, _) = cdr_encoding::from_bytes::<DescriptionMsg, LittleEndian>(&cdr(&big)).unwrap();
        assert_eq!(m, DescriptionMsg::TooLarge(big.len()));
        // A length past the bytes present, and text that is not UTF-8, do not decode.
        let mut cut = cdr("<robot/>");
        cut.truncate(6);
        assert!(cdr_encoding::from_bytes::<DescriptionMsg, LittleEndian>(&cut).is_err());
        let mut bad = cdr("<robot/>");
        bad[5] = 0xff;
        assert!(cdr_encoding::from_bytes::<DescriptionMsg, LittleEndian>(&bad).is_err());
    }

    #[test]
    fn a_refused_description_names_its_topic_once() {
        let source = "/robot_description topic";
        let line = refusal_line("/robot_description", source, "keeping the current robot", "/robot_description topic: malformed URDF: x\ny");
        assert_eq!(line, "/robot_description rejected, keeping the current robot: malformed URDF: x y");
        // An error about another file keeps its own prefix.
        let line = refusal_line("/robot_description", source, "keeping the current robot", "env.urdf: link 'a': bad");
        assert_eq!(line, "/robot_description rejected, keeping the current robot: env.urdf: link 'a': bad");
    }
}
