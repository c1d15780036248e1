//! CDR with the 4-byte encapsulation header that ROS 2 puts before every payload.

use serde::de::DeserializeOwned;
use serde::Serialize;

/// A payload that does not decode.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CdrError {
    /// Shorter than the encapsulation header.
    #[error("message of {0} bytes is shorter than the 4-byte CDR header")]
    Short(usize),
    /// An encapsulation other than plain CDR (e.g. XCDR2, PL_CDR).
    #[error("unsupported CDR encapsulation {0:#04x}{1:02x}")]
    Encapsulation(u8, u8),
    /// The payload does not match the type.
    #[error("CDR payload does not decode as {type_name}: {message}")]
    Payload {
        /// Expected type.
        type_name: &'static str,
        /// What the decoder said.
        message: String,
    },
}

/// Decodes a ROS 2 CDR message (encapsulation header, then little or big endian payload).
pub fn decode_cdr<T: DeserializeOwned>(data: &[u8]) -> Result<T, CdrError> {
    if data.len() < 4 {
        return Err(CdrError::Short(data.len()));
    }
    let payload = &data[4..];
    let result = match (data[0], data[1]) {
        (0x00, 0x01) => cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(payload),
        (0x00, 0x00) => cdr_encoding::from_bytes::<T, byteorder::BigEndian>(payload),
        (a, b) => return Err(CdrError::Encapsulation(a, b)),
    };
    result.map(|(v, _)| v).map_err(|e| CdrError::Payload { type_name: std::any::type_name::<T>(), message: e.to_string() })
}

/// Encodes a message as little-endian CDR with its encapsulation header.
pub fn encode_cdr_le<T: Serialize>(msg: &T) -> Vec<u8> {
    let mut out = Vec::new();
    encode_cdr_le_into(&mut out, msg);
    out
}

/// As [`encode_cdr_le`], into `out` (cleared first): a writer that reuses one buffer allocates
/// nothing per message.
pub(crate) fn encode_cdr_le_into<T: Serialize>(out: &mut Vec<u8>, msg: &T) {
    out.clear();
    out.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
    // Alignment counts from the first byte the serialiser writes, after the header, as CDR wants.
    // Serialising our own plain structs into a Vec cannot fail.
    if let Err(e) = cdr_encoding::to_writer::<T, byteorder::LittleEndian, _>(&mut *out, msg) {
        unreachable!("CDR serialisation of an in-memory message failed: {e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{JointState, MAX_JOINT_STATE_ENTRIES};

    #[test]
    fn a_joint_state_past_the_entry_bound_is_refused_while_decoding() {
        let at = |n: usize| JointState { name: vec!["j".into(); n], position: vec![0.5; n], ..Default::default() };
        let ok: JointState = decode_cdr(&encode_cdr_le(&at(MAX_JOINT_STATE_ENTRIES))).unwrap();
        assert_eq!(ok.name.len(), MAX_JOINT_STATE_ENTRIES);
        let e = decode_cdr::<JointState>(&encode_cdr_le(&at(MAX_JOINT_STATE_ENTRIES + 1))).unwrap_err().to_string();
        assert!(e.contains("65537 entries; at most 65536 allowed") || e.contains("more than 65536 entries"), "{e}");
    }
}
