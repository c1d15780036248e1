//! The input format of the `cdr` target: a sequence of CDR messages, each tagged with the kind
//! of message the node would decode it as.

/// The message kinds of the [`cdr`](crate::cdr) target, by the record's kind byte (modulo their
/// count).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CdrKind {
    /// `joint_states` (`sensor_msgs/msg/JointState`).
    JointStates = 0,
    /// `/tf` (`tf2_msgs/msg/TFMessage`).
    Tf = 1,
    /// `/tf_static`.
    TfStatic = 2,
    /// `robot_description` (`std_msgs/msg/String`).
    Description = 3,
    /// A `check_states` request.
    CheckStates = 4,
    /// `/clock`.
    Clock = 5,
}

/// Every kind, in kind-byte order.
pub(crate) const CDR_KINDS: [CdrKind; 6] = [CdrKind::JointStates, CdrKind::Tf, CdrKind::TfStatic, CdrKind::Description, CdrKind::CheckStates, CdrKind::Clock];

/// One input of the [`cdr`](crate::cdr) target: records of `[kind: u8][length: u16 LE][payload]`,
/// the last one taking what is left when its length runs past the end. Used to write seeds.
pub fn cdr_records(records: &[(CdrKind, Vec<u8>)]) -> Vec<u8> {
    let mut out = Vec::new();
    for (kind, payload) in records {
        out.push(*kind as u8);
        out.extend_from_slice(&(payload.len().min(u16::MAX as usize) as u16).to_le_bytes());
        out.extend_from_slice(&payload[..payload.len().min(u16::MAX as usize)]);
    }
    out
}

/// The records of a [`cdr`](crate::cdr) input, as the target reads them.
pub fn split_records(mut data: &[u8]) -> Vec<(CdrKind, &[u8])> {
    let mut out = Vec::new();
    while let [kind, rest @ ..] = data {
        let kind = CDR_KINDS[*kind as usize % CDR_KINDS.len()];
        let (len, rest) = match rest {
            [a, b, rest @ ..] => (u16::from_le_bytes([*a, *b]) as usize, rest),
            _ => (rest.len(), &rest[rest.len()..]),
        };
        let n = len.min(rest.len());
        out.push((kind, &rest[..n]));
        data = &rest[n..];
    }
    out
}
