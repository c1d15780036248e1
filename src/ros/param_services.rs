//! The node's parameter services (`rcl_interfaces`: get, get types, set, set atomically, list,
//! describe) with the node's `service_mapping`, served by the node in every mapping.
//!
//! ros2-client 0.12 starts these services itself only with the enhanced mapping (its `node.rs`:
//! `let service_mapping = ServiceMapping::Enhanced; //TODO: parameterize`), where the request id
//! travels as the sample identity. `ros2 param` on `rmw_cyclonedds_cpp` puts it in the payload
//! (the Cyclone mapping) and could not reach them; and ros2-client describes every parameter as
//! writable. So the node turns ros2-client's services off and serves the same six here, from the node's own parameter store:
//! `Node::get_parameter`, and `Node::set_parameter`, which runs the same rules (declared name,
//! type kept), the node's set action (validation, the change handed to the loop) and publishes
//! `/parameter_events`. The answers are those ros2-client gives (its `Spinner::spin`), except
//! that the parameters the node fixes at start and those `read_only_parameters` names are
//! described `read_only`.

use super::param_values::ReadOnly;
use anyhow::{anyhow, Result};
use futures::stream::{FusedStream, StreamExt};
use ros2_client::parameters::{raw, ParameterDescriptor, ParameterValue};
use ros2_client::qos::{History, WhenFull};
use ros2_client::rcl_interfaces::{
    DescribeParametersRequest, DescribeParametersResponse, GetParameterTypesRequest, GetParameterTypesResponse, GetParametersRequest, GetParametersResponse,
    ListParametersRequest, ListParametersResponse, ListParametersResult, SetParametersAtomicallyResponse, SetParametersRequest, SetParametersResponse,
};
use ros2_client::service::RmwRequestId;
use ros2_client::{Name, Node, QosProfile, ReadResult, Server, ServiceMapping, ServiceTypeName};
use std::pin::Pin;

/// One request to any of the six services.
pub(crate) enum ParamRequest {
    /// `get_parameters`.
    Get(RmwRequestId, GetParametersRequest),
    /// `get_parameter_types`.
    GetTypes(RmwRequestId, GetParameterTypesRequest),
    /// `set_parameters`.
    Set(RmwRequestId, SetParametersRequest),
    /// `set_parameters_atomically`.
    SetAtomically(RmwRequestId, SetParametersRequest),
    /// `list_parameters`.
    List(RmwRequestId, ListParametersRequest),
    /// `describe_parameters`.
    Describe(RmwRequestId, DescribeParametersRequest),
}

/// The six servers.
pub(crate) struct ParamServers {
    get: Server<GetParametersRequest, GetParametersResponse>,
    get_types: Server<GetParameterTypesRequest, GetParameterTypesResponse>,
    set: Server<SetParametersRequest, SetParametersResponse>,
    set_atomically: Server<SetParametersRequest, SetParametersAtomicallyResponse>,
    list: Server<ListParametersRequest, ListParametersResponse>,
    describe: Server<DescribeParametersRequest, DescribeParametersResponse>,
    read_only: ReadOnly,
}

/// Every request of the six services, in arrival order per service.
pub(crate) type ParamRequests<'a> = Pin<Box<dyn FusedStream<Item = ReadResult<ParamRequest>> + 'a>>;

/// The node's `service_mapping` parameter as ros2-client's mapping.
pub(crate) fn ros_mapping(mapping: crate::model::ServiceMapping) -> ServiceMapping {
    match mapping {
        crate::model::ServiceMapping::Enhanced => ServiceMapping::Enhanced,
        crate::model::ServiceMapping::Basic => ServiceMapping::Basic,
        crate::model::ServiceMapping::Cyclone => ServiceMapping::Cyclone,
    }
}

impl ParamServers {
    /// The servers under the node's name (`<node>/get_parameters`, ...) with `mapping`, describing
    /// `read_only`'s parameters as read only.
    pub(crate) fn build(node: &mut Node, mapping: ServiceMapping, read_only: ReadOnly) -> Result<Option<ParamServers>> {
        // rmw_qos_profile_services_default: reliable, volatile, keep last 10.
        let qos = QosProfile::publisher_default().reliability_reliable(WhenFull::DEFAULT).history(History::KeepLast { depth: 10 });
        let fqn = node.fully_qualified_name();
        let name = |service: &str| Name::new(&fqn, service).map_err(|e| anyhow!("parameter service {fqn}/{service}: {e:?}"));
        let ty = |t: &str| ServiceTypeName::new("rcl_interfaces", t);
        let err = |service: &'static str| move |e| anyhow!("parameter service {service}: {e:?}");
        Ok(Some(ParamServers {
            get: node.create_server(mapping, &name("get_parameters")?, &ty("GetParameters"), qos.clone(), qos.clone()).map_err(err("get_parameters"))?,
            get_types: node
                .create_server(mapping, &name("get_parameter_types")?, &ty("GetParameterTypes"), qos.clone(), qos.clone())
                .map_err(err("get_parameter_types"))?,
            set: node.create_server(mapping, &name("set_parameters")?, &ty("SetParameters"), qos.clone(), qos.clone()).map_err(err("set_parameters"))?,
            set_atomically: node
                .create_server(mapping, &name("set_parameters_atomically")?, &ty("SetParametersAtomically"), qos.clone(), qos.clone())
                .map_err(err("set_parameters_atomically"))?,
            list: node.create_server(mapping, &name("list_parameters")?, &ty("ListParameters"), qos.clone(), qos.clone()).map_err(err("list_parameters"))?,
            describe: node
                .create_server(mapping, &name("describe_parameters")?, &ty("DescribeParameters"), qos.clone(), qos)
                .map_err(err("describe_parameters"))?,
            read_only,
        }))
    }

    /// The requests of all six services as one stream (never ends while the servers live).
    pub(crate) fn requests(&self) -> ParamRequests<'_> {
        let streams: Vec<Pin<Box<dyn futures::Stream<Item = ReadResult<ParamRequest>> + '_>>> = vec![
            Box::pin(self.get.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::Get(id, q)))),
            Box::pin(self.get_types.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::GetTypes(id, q)))),
            Box::pin(self.set.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::Set(id, q)))),
            Box::pin(self.set_atomically.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::SetAtomically(id, q)))),
            Box::pin(self.list.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::List(id, q)))),
            Box::pin(self.describe.receive_request_stream().map(|r| r.map(|(id, q)| ParamRequest::Describe(id, q)))),
        ];
        Box::pin(futures::stream::select_all(streams))
    }

    /// Answers one request from the node's parameters; `Err` names the service whose answer could
    /// not be sent.
    pub async fn answer(&self, node: &Node, request: ParamRequest) -> Result<(), &'static str> {
        match request {
            ParamRequest::Get(id, q) => {
                let values = q.names.iter().map(|n| raw::ParameterValue::from(node.get_parameter(n).unwrap_or(ParameterValue::NotSet))).collect();
                self.get.async_send_response(id, GetParametersResponse { values }).await.map_err(|_| "get_parameters")
            }
            ParamRequest::GetTypes(id, q) => {
                let values = q.names.iter().map(|n| ParameterValue::to_parameter_type_raw(&node.get_parameter(n).unwrap_or(ParameterValue::NotSet))).collect();
                self.get_types.async_send_response(id, GetParameterTypesResponse { values }).await.map_err(|_| "get_parameter_types")
            }
            ParamRequest::Set(id, q) => {
                let results = q.parameter.into_iter().map(|p| raw::SetParametersResult::from(node.set_parameter(&p.name, p.value.into()))).collect();
                self.set.async_send_response(id, SetParametersResponse { results }).await.map_err(|_| "set_parameters")
            }
            ParamRequest::SetAtomically(id, q) => {
                let result = raw::SetParametersResult::from(set_in_turn(node, q.parameter));
                self.set_atomically.async_send_response(id, SetParametersAtomicallyResponse { result }).await.map_err(|_| "set_parameters_atomically")
            }
            ParamRequest::List(id, q) => {
                let result = list(&node.list_parameters(), &q.prefixes, q.depth);
                self.list.async_send_response(id, ListParametersResponse { result }).await.map_err(|_| "list_parameters")
            }
            ParamRequest::Describe(id, q) => {
                let values = q.names.iter().map(|n| describe(n, node.get_parameter(n), &self.read_only)).collect();
                self.describe.async_send_response(id, DescribeParametersResponse { values }).await.map_err(|_| "describe_parameters")
            }
        }
    }
}

/// `set_parameters_atomically`: every name declared and every type kept is checked before any
/// value is set (the store's own rules); then the values are set in turn. ros2-client's public
/// API has no transaction, so a value the node's validation refuses after others were set leaves
/// those set, and the reason says so.
fn set_in_turn(node: &Node, params: Vec<raw::Parameter>) -> Result<(), String> {
    let params: Vec<(String, ParameterValue)> = params.into_iter().map(|p| (p.name, ParameterValue::from(p.value))).collect();
    for (name, value) in &params {
        match node.get_parameter(name) {
            None => return Err(format!("Setting undeclared parameter '{name}' is not allowed.")),
            Some(old) if old.to_parameter_type() != value.to_parameter_type() => {
                return Err(format!("parameter '{name}' is {:?}, not {:?}", old.to_parameter_type(), value.to_parameter_type()))
            }
            Some(_) => {}
        }
    }
    for (k, (name, value)) in params.into_iter().enumerate() {
        node.set_parameter(&name, value).map_err(|e| if k == 0 { e } else { format!("{e} ({k} parameters before it were set)") })?;
    }
    Ok(())
}

/// `list_parameters` as rclcpp answers it (and ros2-client's store): with no prefixes, the names
/// with fewer than `depth` dots (0: any); else the names equal to a prefix or under `prefix.`
/// within `depth` further levels; `prefixes` are the distinct namespaces of the names listed.
fn list(names: &[String], prefixes: &[String], depth: u64) -> ListParametersResult {
    let within_depth = |s: &str| depth == 0 || (s.matches('.').count() as u64) < depth;
    let mut result = ListParametersResult { names: vec![], prefixes: vec![] };
    for name in names {
        let all = prefixes.is_empty() && within_depth(name);
        let under = prefixes.iter().any(|prefix| {
            name == prefix || name.strip_prefix(prefix.as_str()).and_then(|rest| rest.strip_prefix('.')).is_some_and(|rest| within_depth(&format!(".{rest}")))
        });
        if all || under {
            result.names.push(name.clone());
            if let Some((namespace, _)) = name.rsplit_once('.') {
                if !result.prefixes.iter().any(|p| p == namespace) {
                    result.prefixes.push(namespace.to_owned());
                }
            }
        }
    }
    result
}

fn describe(name: &str, value: Option<ParameterValue>, read_only: &ReadOnly) -> raw::ParameterDescriptor {
    let mut d = match &value {
        Some(v) => ParameterDescriptor::from_value(name, v),
        None => ParameterDescriptor::unknown(name),
    };
    if value.is_some() {
        d.read_only = read_only.reason(name).is_some();
        d.description = String::new();
    }
    raw::ParameterDescriptor::from(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn list_follows_rclcpp() {
        let all = names(&["a", "padding.links", "padding.values", "thin_surfaces.side", "x.y.z"]);
        let r = list(&all, &[], 0);
        assert_eq!(r.names, all);
        assert_eq!(r.prefixes, names(&["padding", "thin_surfaces", "x.y"]));
        assert_eq!(list(&all, &[], 1).names, names(&["a"]));
        assert_eq!(list(&all, &[], 2).names, names(&["a", "padding.links", "padding.values", "thin_surfaces.side"]));
        let r = list(&all, &names(&["padding"]), 0);
        assert_eq!((r.names, r.prefixes), (names(&["padding.links", "padding.values"]), names(&["padding"])));
        assert_eq!(list(&all, &names(&["x"]), 1).names, Vec::<String>::new());
        // rclcpp counts the separators after the prefix, the leading one included (".y.z": 2).
        assert_eq!(list(&all, &names(&["x"]), 2).names, Vec::<String>::new());
        assert_eq!(list(&all, &names(&["x"]), 3).names, names(&["x.y.z"]));
        assert_eq!(list(&all, &names(&["a"]), 0).names, names(&["a"]));
    }

    #[test]
    fn describe_marks_the_fixed_parameters_read_only() {
        let params = crate::model::Params { read_only_parameters: vec!["thin_surfaces.*".into()], ..Default::default() };
        let ro = ReadOnly::of(&params);
        let d = describe("service_mapping", Some(ParameterValue::String("cyclone".into())), &ro);
        assert!(d.read_only && d.r#type == raw::ParameterType::STRING);
        let d = describe("default_thickness", Some(ParameterValue::Double(0.02)), &ro);
        assert!(!d.read_only && d.r#type == raw::ParameterType::DOUBLE);
        let d = describe("thin_surfaces.thickness", Some(ParameterValue::DoubleArray(vec![])), &ro);
        assert!(d.read_only);
        assert!(describe("read_only_parameters", Some(ParameterValue::StringArray(vec![])), &ro).read_only);
        let d = describe("no_such", None, &ro);
        assert_eq!(d.r#type, raw::ParameterType::NOT_SET);
    }
}
