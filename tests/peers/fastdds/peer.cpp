// An independent ROS 2 participant on eProsima Fast DDS (Debian's libfastrtps 2.9), speaking to
// the node as a ROS 2 program on rmw_fastrtps_cpp would: topics rt/<name>, services
// rq/<service>Request and rr/<service>Reply (the enhanced request/reply mapping: the request id
// travels as the sample identity), type names pkg::msg::dds_::Type_ (fastddsgen -typeros2, from the
// Python peers' field lists through ros_idl.py). Built by build.sh; driven by tests/fastdds_interop.rs
// through tests/common/fastdds.rs.
//
// Transport: UDPv4 only (built-in transports off: no shared memory), on the interface given with
// --interface (127.0.0.1 unless told otherwise), initial peers --peer (127.0.0.1 unless told), no
// data sharing. Domain: --domain, else ROS_DOMAIN_ID. The PID of the related sample identity:
// --related-sample-identity-pid, else TC_FASTDDS_RELATED_SAMPLE_IDENTITY_PID, else 0x800f (see below).
// The UDP socket receive buffer: --receive-buffer, else TC_FASTDDS_RECEIVE_BUFFER, else Fast DDS's
// default (0: the OS default, net.core.rmem_default), as rmw_fastrtps_cpp leaves it.
//
// The client does what rmw_fastrtps_cpp's client does (rmw_fastrtps_shared_cpp, rmw_request.cpp and
// custom_client_info.hpp): it writes each request with WriteParams whose
// related_sample_identity().writer_guid() is its reply reader's GUID (sequence number unknown), keeps
// the sample identity the write gave the request, and accepts a reply only when the reply's related
// sample identity names the reply reader's GUID or the request writer's GUID and carries that
// request's sequence number. Other replies are counted as rejected.
//
// Protocol: one JSON command per line on stdin, one JSON answer per line on stdout (stderr: log).
//   {"cmd":"hello"}
//   {"cmd":"states","ns":"","input":"joint_states"|"tf","states":[S...],"warm":S,"timeout":s}
//       S = {"name":[...],"position":[...],"stamp":ns} or, for tf, {"stamp":ns,"transforms":[
//       {"parent","child","translation":[3],"rotation":[4]}]}. Warm-up: "warm" is sent every 0.5 s
//       until a report arrives (the node has matched our writer); then each state in turn, waiting
//       for one report on rt/<ns>/collisions.  -> {"matched":bool,"warm_reports":n,"reports":[R...]}
//   {"cmd":"description","ns":"","text":"<robot ...>"}   latched writer on rt/<ns>/robot_description
//   {"cmd":"status"}    -> {"description_readers":n}
//   {"cmd":"call","service":"check_states","type":T,"requests":[Q...],"timeout":s,"resend":s}
//       one client (writer + reader) per request, all in flight together;
//       -> {"answers":[{"response":...|null,"attempts":n,"rejected":n,"reply_guid":g,"reply_seq":n}]}
//   {"cmd":"latched","ns":"","timeout":s} -> {"cells":[...]|null,"diagnostics":[...]|null}
//   {"cmd":"pid_stats"} -> {"rewritten":n}: related sample identities sent under another PID than
//       0x800f (--related-sample-identity-pid 0x0083, Jazzy's; see PidRewriteTransport)
//   {"cmd":"apply","service":"apply_planning_scene","files":[PATH...],"timeout":s}
//       timed ApplyPlanningScene calls, each request's CDR bytes from a file (see cmd_apply)
//       -> {"matched":bool,"answers":[{"success":bool|null,"seconds":s}]}
//   {"cmd":"publish","topic":"collision_object","files":[PATH...],"rate":hz,"seconds":s,"timeout":s}
//       CollisionObjects (CDR files) written in turn at `rate` -> {"matched":bool,"sent":n,"late":n}
//   {"cmd":"quit"}
#include "peer_json.hpp"
#include "ros.h"
#include "rosPubSubTypes.h"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/WriteParams.h>
#include <fastdds/rtps/network/SenderResource.h>
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

std::string guid_str(const rtps::GUID_t& g) {
    std::ostringstream o;
    o << g;
    return o.str();
}

int64_t seq_i64(const rtps::SequenceNumber_t& s) { return (static_cast<int64_t>(s.high) << 32) | s.low; }

// ---- messages from and to JSON --------------------------------------------------------------

builtin_interfaces::msg::Time stamp_of(int64_t ns) {
    builtin_interfaces::msg::Time t;
    t.sec(static_cast<int32_t>(ns / 1000000000));
    t.nanosec(static_cast<uint32_t>(ns % 1000000000));
    return t;
}
int64_t ns_of(const builtin_interfaces::msg::Time& t) { return static_cast<int64_t>(t.sec()) * 1000000000 + t.nanosec(); }

sensor_msgs::msg::JointState joint_state(const pj::Value& s) {
    sensor_msgs::msg::JointState m;
    m.header().stamp(stamp_of(s["stamp"].i64()));
    m.name(s["name"].strs());
    m.position(s["position"].nums());
    return m;
}

tf2_msgs::msg::TFMessage tf_message(const pj::Value& s) {
    tf2_msgs::msg::TFMessage m;
    for (const auto& x : s["transforms"].arr()) {
        geometry_msgs::msg::TransformStamped t;
        t.header().stamp(stamp_of(s["stamp"].i64()));
        t.header().frame_id(x["parent"].str());
        t.child_frame_id(x["child"].str());
        auto tr = x["translation"].nums(), r = x["rotation"].nums();
        if (tr.size() == 3) {
            t.transform().translation().x(tr[0]);
            t.transform().translation().y(tr[1]);
            t.transform().translation().z(tr[2]);
        }
        if (r.size() == 4) {
            t.transform().rotation().x(r[0]);
            t.transform().rotation().y(r[1]);
            t.transform().rotation().z(r[2]);
            t.transform().rotation().w(r[3]);
        }
        m.transforms().push_back(t);
    }
    return m;
}

std::string vec3(double x, double y, double z) { return pj::nums({x, y, z}); }

std::string contact_json(const thickness_collision_msgs::msg::Contact& c) {
    return pj::Obj()
        .add("link_name", pj::quote(c.link_name()))
        .add("object_name", pj::quote(c.object_name()))
        .add("triangle", pj::integer(c.triangle()))
        .add("depth", pj::number(c.depth()))
        .add("position", vec3(c.position().x(), c.position().y(), c.position().z()))
        .add("normal", vec3(c.normal().x(), c.normal().y(), c.normal().z()))
        .add("object_type", pj::quote(c.object_type() == 1 ? "robot_link" : "environment"))
        .str();
}

std::string report_json(const thickness_collision_msgs::msg::CollisionReport& r) {
    return pj::Obj()
        .add("in_collision", pj::boolean(r.in_collision()))
        .add("stamp", pj::integer(ns_of(r.header().stamp())))
        .add("frame_id", pj::quote(r.header().frame_id()))
        .add("contacts", pj::array(r.contacts(), contact_json))
        .add("check_seconds", pj::number(r.check_seconds()))
        .add("error", pj::quote(r.error()))
        .add("motion", pj::boolean(r.motion()))
        .add("fraction", pj::number(r.fraction()))
        .add("clearances", pj::integer(static_cast<int64_t>(r.clearances().size())))
        .str();
}

rcl_interfaces::msg::ParameterValue parameter_value(const pj::Value& v) {
    rcl_interfaces::msg::ParameterValue p;
    p.type(static_cast<uint8_t>(v["type"].i64()));
    p.bool_value(v["bool"].boolean());
    p.integer_value(v["integer"].i64());
    p.double_value(v["double"].num());
    p.string_value(v["string"].str());
    p.double_array_value(v["double_array"].nums());
    p.string_array_value(v["string_array"].strs());
    for (const auto& x : v["integer_array"].arr()) p.integer_array_value().push_back(x.i64());
    for (const auto& x : v["bool_array"].arr()) p.bool_array_value().push_back(x.boolean());
    return p;
}

std::string parameter_value_json(const rcl_interfaces::msg::ParameterValue& p) {
    std::vector<int64_t> ints(p.integer_array_value().begin(), p.integer_array_value().end());
    std::vector<bool> bools(p.bool_array_value().begin(), p.bool_array_value().end());
    return pj::Obj()
        .add("type", pj::integer(p.type()))
        .add("bool", pj::boolean(p.bool_value()))
        .add("integer", pj::integer(p.integer_value()))
        .add("double", pj::number(p.double_value()))
        .add("string", pj::quote(p.string_value()))
        .add("double_array", pj::nums(p.double_array_value()))
        .add("string_array", pj::strs(p.string_array_value()))
        .add("integer_array", pj::array(ints, [](int64_t x) { return pj::integer(x); }))
        .add("bool_array", pj::array(bools, [](bool x) { return pj::boolean(x); }))
        .str();
}

// ---- QoS as rmw_fastrtps_cpp sets it ---------------------------------------------------------

struct Qos {
    bool reliable = true;
    bool latched = false;
    int32_t depth = 10;
};

DataWriterQos writer_qos(const Qos& q) {
    DataWriterQos w = DATAWRITER_QOS_DEFAULT;
    w.reliability().kind = q.reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    w.durability().kind = q.latched ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
    w.history().kind = KEEP_LAST_HISTORY_QOS;
    w.history().depth = q.depth;
    // rmw_fastrtps: variable-size types, payloads grown as needed; synchronous publication.
    w.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    w.publish_mode().kind = SYNCHRONOUS_PUBLISH_MODE;
    w.data_sharing().off();
    return w;
}

DataReaderQos reader_qos(const Qos& q) {
    DataReaderQos r = DATAREADER_QOS_DEFAULT;
    r.reliability().kind = q.reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    r.durability().kind = q.latched ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
    r.history().kind = KEEP_LAST_HISTORY_QOS;
    r.history().depth = q.depth;
    r.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    r.data_sharing().off();
    return r;
}

// rmw_qos_profile_services_default: reliable, volatile, keep last 10.
const Qos kServiceQos{true, false, 10};

// ---- Jazzy's related sample identity ---------------------------------------------------------
//
// Fast DDS 2.9 (Humble) writes the related sample identity of a request as PID 0x800f
// (PID_CUSTOM_RELATED_SAMPLE_IDENTITY); Fast DDS 2.14 (Jazzy) writes the standard PID 0x0083 (DDS-RPC
// 7.8.2). Jazzy's Fast DDS cannot be installed here, so with --related-sample-identity-pid 0x0083 the
// peer sends that form itself: a chaining transport over UDPv4 rewrites, in every outgoing RTPS DATA
// submessage, the inline QoS parameter 0x800f to 0x0083 (same length and value). Only 0x0083 is
// then on the wire, which is stricter than Jazzy (it writes both).

std::atomic<uint64_t> g_rewritten{0};
// The PID the related sample identity is sent as: 0x800f (Fast DDS 2.9, no rewriting), 0x0083 (Jazzy),
// or another (a control: a PID the node does not know).
uint16_t g_pid = 0x800f;

// Rewrites PID `from` to `to` in the inline QoS of the DATA submessages of one RTPS message.
void rewrite_pid(std::vector<rtps::octet>& m, uint16_t from, uint16_t to) {
    if (m.size() < 20 || std::memcmp(m.data(), "RTPS", 4) != 0) return;
    size_t at = 20;  // after the RTPS header
    while (at + 4 <= m.size()) {
        uint8_t id = m[at], flags = m[at + 1];
        bool le = flags & 0x01;
        auto u16 = [&](size_t i) -> uint16_t { return le ? uint16_t(m[i] | (m[i + 1] << 8)) : uint16_t((m[i] << 8) | m[i + 1]); };
        size_t body = at + 4;
        size_t length = u16(at + 2);
        size_t end = length == 0 ? m.size() : std::min(m.size(), body + length);
        if (id == 0x15 && (flags & 0x02) && body + 4 <= end) {  // DATA with inline QoS
            size_t q = body + 4 + u16(body + 2);  // after extraFlags, octetsToInlineQos and what it skips
            while (q + 4 <= end) {
                uint16_t pid = u16(q), plen = u16(q + 2);
                if (pid == 0x0001) break;  // PID_SENTINEL
                if (pid == from) {
                    m[q] = le ? uint8_t(to & 0xff) : uint8_t(to >> 8);
                    m[q + 1] = le ? uint8_t(to >> 8) : uint8_t(to & 0xff);
                    ++g_rewritten;
                }
                q += 4 + plen;
            }
        }
        if (length == 0) break;
        at = body + length;
    }
}

struct PidRewriteDescriptor : public eprosima::fastdds::rtps::ChainingTransportDescriptor {
    explicit PidRewriteDescriptor(std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> low);
    eprosima::fastdds::rtps::TransportInterface* create_transport() const override;
};

class PidRewriteTransport : public eprosima::fastdds::rtps::ChainingTransport {
public:
    explicit PidRewriteTransport(const PidRewriteDescriptor& d) : ChainingTransport(d), descriptor_(d) {}
    eprosima::fastdds::rtps::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }
    bool send(rtps::SenderResource* low, const rtps::octet* buffer, uint32_t size, rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end,
              const std::chrono::steady_clock::time_point& timeout) override {
        std::vector<rtps::octet> copy(buffer, buffer + size);
        rewrite_pid(copy, 0x800f, g_pid);
        return low->send(copy.data(), size, begin, end, timeout);
    }
    void receive(eprosima::fastdds::rtps::TransportReceiverInterface* next, const rtps::octet* buffer, uint32_t size, const rtps::Locator_t& local,
                 const rtps::Locator_t& remote) override {
        next->OnDataReceived(buffer, size, local, remote);
    }

private:
    PidRewriteDescriptor descriptor_;
};

PidRewriteDescriptor::PidRewriteDescriptor(std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> low) : ChainingTransportDescriptor(low) {}
eprosima::fastdds::rtps::TransportInterface* PidRewriteDescriptor::create_transport() const { return new PidRewriteTransport(*this); }

// ---- the participant -------------------------------------------------------------------------

class Peer {
public:
    Peer(int domain, const std::string& interface, const std::vector<std::string>& peers, bool rewrite, uint32_t receive_buffer) : domain_(domain) {
        DomainParticipantQos pq = PARTICIPANT_QOS_DEFAULT;
        pq.name("tc_fastdds_peer");
        pq.transport().use_builtin_transports = false;
        auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
        udp->interfaceWhiteList.push_back(interface);
        if (receive_buffer > 0) udp->receiveBufferSize = receive_buffer;
        if (rewrite) pq.transport().user_transports.push_back(std::make_shared<PidRewriteDescriptor>(udp));
        else pq.transport().user_transports.push_back(udp);
        // Initial peers: the well-known metatraffic unicast ports of participants 0..19 on each
        // peer address (port = 7400 + 250 domain + 10 + 2 id), as Fast DDS expands a port-less peer.
        for (const auto& address : peers) {
            for (uint32_t id = 0; id < 20; ++id) {
                rtps::Locator_t loc;
                eprosima::fastrtps::rtps::IPLocator::setIPv4(loc, address);
                loc.port = 7400 + 250 * static_cast<uint32_t>(domain) + 10 + 2 * id;
                pq.wire_protocol().builtin.initialPeersList.push_back(loc);
            }
        }
        dp_ = DomainParticipantFactory::get_instance()->create_participant(domain, pq);
        if (dp_ == nullptr) throw std::runtime_error("cannot create the Fast DDS participant");
        pub_ = dp_->create_publisher(PUBLISHER_QOS_DEFAULT);
        sub_ = dp_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    }

    ~Peer() {
        for (auto& [name, w] : writers_) pub_->delete_datawriter(w);
        for (auto& [name, r] : readers_) sub_->delete_datareader(r);
        dp_->delete_contained_entities();
        DomainParticipantFactory::get_instance()->delete_participant(dp_);
    }

    std::string guid() const { return guid_str(dp_->guid()); }

    // The type registered under its ROS 2 DDS name; returns that name.
    template <class PubSubType>
    std::string type() {
        TypeSupport ts(new PubSubType());
        std::string name = ts.get_type_name();
        if (!types_.count(name)) {
            if (ts.register_type(dp_) != ReturnCode_t::RETCODE_OK) throw std::runtime_error("cannot register " + name);
            types_[name] = ts;
        }
        return name;
    }

    Topic* topic(const std::string& name, const std::string& type_name) {
        auto it = topics_.find(name);
        if (it != topics_.end()) return it->second;
        Topic* t = dp_->create_topic(name, type_name, TOPIC_QOS_DEFAULT);
        if (t == nullptr) throw std::runtime_error("cannot create topic " + name);
        topics_[name] = t;
        return t;
    }

    // Writers and readers kept for the peer's life, by key (topic name).
    template <class PubSubType>
    DataWriter* writer(const std::string& topic_name, const Qos& q) {
        auto it = writers_.find(topic_name);
        if (it != writers_.end()) return it->second;
        DataWriter* w = pub_->create_datawriter(topic(topic_name, type<PubSubType>()), writer_qos(q));
        if (w == nullptr) throw std::runtime_error("cannot create a writer on " + topic_name);
        writers_[topic_name] = w;
        return w;
    }

    template <class PubSubType>
    DataReader* reader(const std::string& topic_name, const Qos& q) {
        auto it = readers_.find(topic_name);
        if (it != readers_.end()) return it->second;
        DataReader* r = sub_->create_datareader(topic(topic_name, type<PubSubType>()), reader_qos(q));
        if (r == nullptr) throw std::runtime_error("cannot create a reader on " + topic_name);
        readers_[topic_name] = r;
        return r;
    }

    Publisher* publisher() { return pub_; }
    Subscriber* subscriber() { return sub_; }

private:
    int domain_;
    DomainParticipant* dp_ = nullptr;
    Publisher* pub_ = nullptr;
    Subscriber* sub_ = nullptr;
    std::map<std::string, TypeSupport> types_;
    std::map<std::string, Topic*> topics_;
    std::map<std::string, DataWriter*> writers_;
    std::map<std::string, DataReader*> readers_;
};

int writer_matches(DataWriter* w) {
    PublicationMatchedStatus s;
    w->get_publication_matched_status(s);
    return s.current_count;
}

int reader_matches(DataReader* r) {
    SubscriptionMatchedStatus s;
    r->get_subscription_matched_status(s);
    return s.current_count;
}

bool wait_for(const std::function<bool()>& ok, double timeout) {
    double end = now_s() + timeout;
    while (!ok()) {
        if (now_s() > end) return false;
        sleep_s(0.02);
    }
    return true;
}

// Every valid sample waiting in `r`, as JSON by `show`.
template <class Msg>
std::vector<std::string> take_all(DataReader* r, const std::function<std::string(const Msg&)>& show) {
    std::vector<std::string> out;
    Msg m;
    SampleInfo info;
    while (r->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) out.push_back(show(m));
    }
    return out;
}

std::string ns_prefix(const pj::Value& cmd) {
    std::string ns = cmd["ns"].str();
    while (!ns.empty() && ns.back() == '/') ns.pop_back();
    return ns;  // "" or "/robot1"
}

// ---- commands --------------------------------------------------------------------------------

std::string cmd_states(Peer& peer, const pj::Value& cmd) {
    using Report = thickness_collision_msgs::msg::CollisionReport;
    std::string ns = ns_prefix(cmd);
    bool tf = cmd["input"].str("joint_states") == "tf";
    double timeout = cmd["timeout"].num(30);
    // A robot driver's joint_state_broadcaster and tf2's broadcaster publish reliable, keep last
    // (10 and 100): the node's best-effort readers match them.
    DataWriter* w = tf ? peer.writer<tf2_msgs::msg::TFMessagePubSubType>("rt/tf", Qos{true, false, 100})
                       : peer.writer<sensor_msgs::msg::JointStatePubSubType>("rt" + ns + "/joint_states", Qos{true, false, 10});
    DataReader* r = peer.reader<thickness_collision_msgs::msg::CollisionReportPubSubType>("rt" + ns + "/collisions", Qos{true, false, 1000});
    bool matched = wait_for([&] { return writer_matches(w) > 0 && reader_matches(r) > 0; }, timeout);
    std::function<std::string(const Report&)> show = report_json;
    auto write = [&](const pj::Value& s) {
        if (tf) {
            auto m = tf_message(s);
            w->write(&m);
        } else {
            auto m = joint_state(s);
            w->write(&m);
        }
    };
    auto collect = [&](size_t n, double wait) {
        std::vector<std::string> got;
        double end = now_s() + wait;
        while (got.size() < n && now_s() < end) {
            for (auto& x : take_all<Report>(r, show)) got.push_back(x);
            sleep_s(0.002);
        }
        return got;
    };
    size_t warm_reports = 0;
    if (cmd.has("warm")) {
        double end = now_s() + std::min(timeout, 15.0);
        while (now_s() < end) {
            write(cmd["warm"]);
            auto got = collect(1, 0.5);
            if (!got.empty()) {
                warm_reports = got.size();
                break;
            }
        }
        warm_reports += collect(1000000, 0.3).size();
    }
    std::vector<std::string> reports;
    for (const auto& s : cmd["states"].arr()) {
        write(s);
        for (auto& x : collect(1, 5.0)) reports.push_back(x);
    }
    return pj::Obj()
        .add("matched", pj::boolean(matched))
        .add("warm_reports", pj::integer(static_cast<int64_t>(warm_reports)))
        .add("reports", pj::array(reports, [](const std::string& x) { return x; }))
        .str();
}

std::string cmd_description(Peer& peer, const pj::Value& cmd) {
    // Latched as robot_state_publisher offers it: reliable, transient local, keep last 1.
    DataWriter* w = peer.writer<std_msgs::msg::StringPubSubType>("rt" + ns_prefix(cmd) + "/robot_description", Qos{true, true, 1});
    std_msgs::msg::String m;
    m.data(cmd["text"].str());
    bool ok = w->write(&m);
    return pj::Obj().add("ok", pj::boolean(ok)).str();
}

std::string cmd_status(Peer& peer, const pj::Value& cmd) {
    DataWriter* w = peer.writer<std_msgs::msg::StringPubSubType>("rt" + ns_prefix(cmd) + "/robot_description", Qos{true, true, 1});
    return pj::Obj().add("description_readers", pj::integer(writer_matches(w))).str();
}

std::string cmd_latched(Peer& peer, const pj::Value& cmd) {
    using Markers = visualization_msgs::msg::MarkerArray;
    using Diag = diagnostic_msgs::msg::DiagnosticArray;
    std::string ns = ns_prefix(cmd);
    // A late joiner, as RViz is: the latched cells come from the node's writer history.
    DataReader* cells = peer.reader<visualization_msgs::msg::MarkerArrayPubSubType>("rt" + ns + "/collision_markers/cells", Qos{true, true, 1});
    DataReader* diag = peer.reader<diagnostic_msgs::msg::DiagnosticArrayPubSubType>("rt/diagnostics", Qos{true, false, 100});
    std::function<std::string(const Markers&)> show_cells = [](const Markers& m) {
        return pj::array(m.markers(), [](const visualization_msgs::msg::Marker& mk) {
            return pj::Obj()
                .add("ns", pj::quote(mk.ns()))
                .add("type", pj::integer(mk.type()))
                .add("points", pj::integer(static_cast<int64_t>(mk.points().size())))
                .add("frame", pj::quote(mk.header().frame_id()))
                .str();
        });
    };
    std::function<std::string(const Diag&)> show_diag = [](const Diag& d) {
        return pj::array(d.status(), [](const diagnostic_msgs::msg::DiagnosticStatus& st) {
            pj::Obj values;
            for (const auto& kv : st.values()) values.add(kv.key(), pj::quote(kv.value()));
            return pj::Obj().add("name", pj::quote(st.name())).add("level", pj::integer(st.level())).add("values", values.str()).str();
        });
    };
    std::string got_cells = "null", got_diag = "null";
    double t0 = now_s(), cells_seconds = -1.0;
    double end = t0 + cmd["timeout"].num(10);
    while (now_s() < end && (got_cells == "null" || got_diag == "null")) {
        for (auto& x : take_all<Markers>(cells, show_cells)) {
            got_cells = x;
            if (cells_seconds < 0) cells_seconds = now_s() - t0;
        }
        for (auto& x : take_all<Diag>(diag, show_diag)) got_diag = x;
        sleep_s(0.01);
    }
    return pj::Obj().add("cells", got_cells).add("cells_seconds", pj::number(cells_seconds)).add("diagnostics", got_diag).str();
}

// One service call per request, each from its own client, all in flight together.
template <class ReqPST, class RespPST, class Req, class Resp>
std::string call(Peer& peer, const pj::Value& cmd, const std::function<Req(const pj::Value&)>& make,
                 const std::function<std::string(const Resp&)>& show) {
    std::string service = cmd["service"].str();
    while (!service.empty() && service.front() == '/') service.erase(0, 1);
    Topic* tq = peer.topic("rq/" + service + "Request", peer.type<ReqPST>());
    Topic* tr = peer.topic("rr/" + service + "Reply", peer.type<RespPST>());
    struct Client {
        DataWriter* w;
        DataReader* r;
        std::vector<int64_t> sent;
        std::string response = "null";
        int attempts = 0, rejected = 0;
        double next = 0.0;
        std::string reply_guid;
        int64_t reply_seq = 0;
    };
    std::vector<Client> clients;
    for (size_t k = 0; k < cmd["requests"].arr().size(); ++k) {
        Client c;
        c.w = peer.publisher()->create_datawriter(tq, writer_qos(kServiceQos));
        c.r = peer.subscriber()->create_datareader(tr, reader_qos(kServiceQos));
        if (c.w == nullptr || c.r == nullptr) throw std::runtime_error("cannot create a client for " + service);
        clients.push_back(c);
    }
    double timeout = cmd["timeout"].num(20), resend = cmd["resend"].num(2.0);
    bool matched = wait_for([&] {
        for (auto& c : clients) {
            if (writer_matches(c.w) == 0 || reader_matches(c.r) == 0) return false;
        }
        return true;
    }, timeout);
    // Our side has matched; the node's reply writer may not have matched our reader yet (a reply
    // to a reader it does not know is lost): a short grace, then resends after `resend` seconds.
    sleep_s(0.2);
    double end = now_s() + timeout;
    auto answered = [&] {
        for (auto& c : clients) {
            if (c.response == "null") return false;
        }
        return true;
    };
    while (matched && !answered() && now_s() < end) {
        for (size_t k = 0; k < clients.size(); ++k) {
            Client& c = clients[k];
            if (c.response != "null" || now_s() < c.next) continue;
            Req req = make(cmd["requests"].arr()[k]);
            rtps::WriteParams wp;
            wp.related_sample_identity().writer_guid(c.r->guid());  // sequence number: unknown
            if (c.w->write(&req, wp)) c.sent.push_back(seq_i64(wp.sample_identity().sequence_number()));
            ++c.attempts;
            c.next = now_s() + resend;
        }
        for (auto& c : clients) {
            Resp resp;
            SampleInfo info;
            while (c.r->take_next_sample(&resp, &info) == ReturnCode_t::RETCODE_OK) {
                if (!info.valid_data) continue;
                const rtps::GUID_t& g = info.related_sample_identity.writer_guid();
                int64_t seq = seq_i64(info.related_sample_identity.sequence_number());
                bool ours = (g == c.r->guid() || g == c.w->guid()) && std::find(c.sent.begin(), c.sent.end(), seq) != c.sent.end();
                if (ours && c.response == "null") {
                    c.response = show(resp);
                    c.reply_guid = guid_str(g);
                    c.reply_seq = seq;
                } else if (!ours) {
                    ++c.rejected;
                }
            }
        }
        sleep_s(0.002);
    }
    std::vector<std::string> answers;
    for (auto& c : clients) {
        answers.push_back(pj::Obj()
                              .add("response", c.response)
                              .add("attempts", pj::integer(c.attempts))
                              .add("rejected", pj::integer(c.rejected))
                              .add("reply_guid", pj::quote(c.reply_guid))
                              .add("reply_seq", pj::integer(c.reply_seq))
                              .add("reader_guid", pj::quote(guid_str(c.r->guid())))
                              .str());
        peer.publisher()->delete_datawriter(c.w);
        peer.subscriber()->delete_datareader(c.r);
    }
    return pj::Obj().add("matched", pj::boolean(matched)).add("answers", pj::array(answers, [](const std::string& x) { return x; })).str();
}

std::string cmd_call(Peer& peer, const pj::Value& cmd) {
    std::string type = cmd["type"].str();
    if (type == "check_states") {
        using Req = thickness_collision_msgs::srv::CheckStates_Request;
        using Resp = thickness_collision_msgs::srv::CheckStates_Response;
        return call<thickness_collision_msgs::srv::CheckStates_RequestPubSubType, thickness_collision_msgs::srv::CheckStates_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                for (const auto& s : q["states"].arr()) r.states().push_back(joint_state(s));
                return r;
            },
            [](const Resp& r) { return pj::Obj().add("reports", pj::array(r.reports(), report_json)).str(); });
    }
    if (type == "check_trajectory") {
        using Req = thickness_collision_msgs::srv::CheckTrajectory_Request;
        using Resp = thickness_collision_msgs::srv::CheckTrajectory_Response;
        return call<thickness_collision_msgs::srv::CheckTrajectory_RequestPubSubType, thickness_collision_msgs::srv::CheckTrajectory_ResponsePubSubType, Req,
                    Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.trajectory().header().frame_id("world");
                r.trajectory().joint_names(q["joint_names"].strs());
                if (q.has("interpolation")) r.interpolation(q["interpolation"].str());
                if (q.has("path_tolerance")) r.path_tolerance(q["path_tolerance"].nums());
                for (const auto& p : q["points"].arr()) {
                    trajectory_msgs::msg::JointTrajectoryPoint pt;
                    pt.positions(p["positions"].nums());
                    int64_t t = p["t"].i64();
                    pt.time_from_start().sec(static_cast<int32_t>(t / 1000000000));
                    pt.time_from_start().nanosec(static_cast<uint32_t>(t % 1000000000));
                    r.trajectory().points().push_back(pt);
                }
                return r;
            },
            [](const Resp& r) {
                return pj::Obj()
                    .add("valid", pj::boolean(r.valid()))
                    .add("segment", pj::integer(r.segment()))
                    .add("fraction", pj::number(r.fraction()))
                    .add("time_from_start", pj::integer(static_cast<int64_t>(r.time_from_start().sec()) * 1000000000 + r.time_from_start().nanosec()))
                    .add("contacts", pj::array(r.contacts(), contact_json))
                    .add("error", pj::quote(r.error()))
                    .str();
            });
    }
    if (type == "check_state_validity") {
        using Req = moveit_msgs::srv::GetStateValidity_Request;
        using Resp = moveit_msgs::srv::GetStateValidity_Response;
        return call<moveit_msgs::srv::GetStateValidity_RequestPubSubType, moveit_msgs::srv::GetStateValidity_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.robot_state().joint_state(joint_state(q));
                r.group_name(q["group_name"].str());
                return r;
            },
            [](const Resp& r) {
                auto contact = [](const moveit_msgs::msg::ContactInformation& c) {
                    return pj::Obj()
                        .add("body_1", pj::quote(c.contact_body_1()))
                        .add("type_1", pj::integer(c.body_type_1()))
                        .add("body_2", pj::quote(c.contact_body_2()))
                        .add("type_2", pj::integer(c.body_type_2()))
                        .add("depth", pj::number(c.depth()))
                        .add("position", vec3(c.position().x(), c.position().y(), c.position().z()))
                        .add("normal", vec3(c.normal().x(), c.normal().y(), c.normal().z()))
                        .add("frame", pj::quote(c.header().frame_id()))
                        .str();
                };
                return pj::Obj()
                    .add("valid", pj::boolean(r.valid()))
                    .add("contacts", pj::array(r.contacts(), contact))
                    .add("cost_sources", pj::integer(static_cast<int64_t>(r.cost_sources().size())))
                    .add("constraint_result", pj::integer(static_cast<int64_t>(r.constraint_result().size())))
                    .str();
            });
    }
    if (type == "get_parameters") {
        using Req = rcl_interfaces::srv::GetParameters_Request;
        using Resp = rcl_interfaces::srv::GetParameters_Response;
        return call<rcl_interfaces::srv::GetParameters_RequestPubSubType, rcl_interfaces::srv::GetParameters_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.names(q["names"].strs());
                return r;
            },
            [](const Resp& r) { return pj::Obj().add("values", pj::array(r.values(), parameter_value_json)).str(); });
    }
    if (type == "set_parameters") {
        using Req = rcl_interfaces::srv::SetParameters_Request;
        using Resp = rcl_interfaces::srv::SetParameters_Response;
        return call<rcl_interfaces::srv::SetParameters_RequestPubSubType, rcl_interfaces::srv::SetParameters_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                for (const auto& p : q["parameters"].arr()) {
                    rcl_interfaces::msg::Parameter par;
                    par.name(p["name"].str());
                    par.value(parameter_value(p["value"]));
                    r.parameters().push_back(par);
                }
                return r;
            },
            [](const Resp& r) {
                return pj::Obj()
                    .add("results", pj::array(r.results(), [](const rcl_interfaces::msg::SetParametersResult& x) {
                        return pj::Obj().add("successful", pj::boolean(x.successful())).add("reason", pj::quote(x.reason())).str();
                    }))
                    .str();
            });
    }
    if (type == "get_parameter_types") {
        using Req = rcl_interfaces::srv::GetParameterTypes_Request;
        using Resp = rcl_interfaces::srv::GetParameterTypes_Response;
        return call<rcl_interfaces::srv::GetParameterTypes_RequestPubSubType, rcl_interfaces::srv::GetParameterTypes_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.names(q["names"].strs());
                return r;
            },
            [](const Resp& r) {
                std::vector<int64_t> types(r.types().begin(), r.types().end());
                return pj::Obj().add("types", pj::array(types, [](int64_t x) { return pj::integer(x); })).str();
            });
    }
    if (type == "set_parameters_atomically") {
        using Req = rcl_interfaces::srv::SetParametersAtomically_Request;
        using Resp = rcl_interfaces::srv::SetParametersAtomically_Response;
        return call<rcl_interfaces::srv::SetParametersAtomically_RequestPubSubType, rcl_interfaces::srv::SetParametersAtomically_ResponsePubSubType, Req,
                    Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                for (const auto& p : q["parameters"].arr()) {
                    rcl_interfaces::msg::Parameter par;
                    par.name(p["name"].str());
                    par.value(parameter_value(p["value"]));
                    r.parameters().push_back(par);
                }
                return r;
            },
            [](const Resp& r) {
                return pj::Obj().add("successful", pj::boolean(r.result().successful())).add("reason", pj::quote(r.result().reason())).str();
            });
    }
    if (type == "list_parameters") {
        using Req = rcl_interfaces::srv::ListParameters_Request;
        using Resp = rcl_interfaces::srv::ListParameters_Response;
        return call<rcl_interfaces::srv::ListParameters_RequestPubSubType, rcl_interfaces::srv::ListParameters_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.prefixes(q["prefixes"].strs());
                r.depth(static_cast<uint64_t>(q["depth"].i64()));
                return r;
            },
            [](const Resp& r) { return pj::Obj().add("names", pj::strs(r.result().names())).add("prefixes", pj::strs(r.result().prefixes())).str(); });
    }
    if (type == "describe_parameters") {
        using Req = rcl_interfaces::srv::DescribeParameters_Request;
        using Resp = rcl_interfaces::srv::DescribeParameters_Response;
        return call<rcl_interfaces::srv::DescribeParameters_RequestPubSubType, rcl_interfaces::srv::DescribeParameters_ResponsePubSubType, Req, Resp>(
            peer, cmd,
            [](const pj::Value& q) {
                Req r;
                r.names(q["names"].strs());
                return r;
            },
            [](const Resp& r) {
                return pj::Obj()
                    .add("descriptors", pj::array(r.descriptors(), [](const rcl_interfaces::msg::ParameterDescriptor& d) {
                        return pj::Obj()
                            .add("name", pj::quote(d.name()))
                            .add("type", pj::integer(d.type()))
                            .add("description", pj::quote(d.description()))
                            .add("read_only", pj::boolean(d.read_only()))
                            .add("dynamic_typing", pj::boolean(d.dynamic_typing()))
                            .str();
                    }))
                    .str();
            });
    }
    throw std::runtime_error("unknown service type '" + type + "'");
}

// The CDR bytes in `path` (encapsulation header first) decoded into the generated type of PST.
template <class PST, class Msg>
Msg decode_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.empty()) throw std::runtime_error("cannot read " + path);
    rtps::SerializedPayload_t payload(static_cast<uint32_t>(bytes.size()));
    std::memcpy(payload.data, bytes.data(), bytes.size());
    payload.length = static_cast<uint32_t>(bytes.size());
    Msg msg;
    PST pst;
    if (!pst.deserialize(&payload, &msg)) throw std::runtime_error(path + " does not decode as " + pst.getName());
    return msg;
}

// Scene traffic: the CollisionObjects of `files` (decoded once, before the clock starts) written
// in turn on rt/<topic> at `rate` Hz for `seconds`, as an application publishes them (reliable,
// volatile, keep last 10: MoveIt's ServicesQoS, what the node's reader asks for).
std::string cmd_publish(Peer& peer, const pj::Value& cmd) {
    using PST = moveit_msgs::msg::CollisionObjectPubSubType;
    using Msg = moveit_msgs::msg::CollisionObject;
    std::vector<Msg> msgs;
    for (const auto& f : cmd["files"].arr()) msgs.push_back(decode_file<PST, Msg>(f.str()));
    if (msgs.empty()) throw std::runtime_error("publish: no files");
    DataWriter* w = peer.writer<PST>("rt/" + cmd["topic"].str(), kServiceQos);
    if (!wait_for([&] { return writer_matches(w) > 0; }, cmd["timeout"].num(20))) return pj::Obj().add("matched", "false").str();
    double period = 1.0 / cmd["rate"].num(20), start = now_s(), end = start + cmd["seconds"].num(5);
    int64_t sent = 0, late = 0;
    for (double next = start; now_s() < end; next += period) {
        double wait = next - now_s();
        if (wait > 0) sleep_s(wait);
        else if (wait < -period / 2) ++late;
        if (w->write(&msgs[static_cast<size_t>(sent) % msgs.size()])) ++sent;
    }
    return pj::Obj().add("matched", "true").add("sent", pj::integer(sent)).add("late", pj::integer(late)).str();
}

// Timed apply_planning_scene calls: each request is an ApplyPlanningScene request whose CDR bytes
// the caller wrote to a file, decoded here into the generated type and written as a typed sample, so Fast DDS serialises it as a C++ client would. One client, matched
// first and warmed up with an empty difference (resent until answered: a reply sent before the
// node's reply writer matched our reader is lost); then each request in turn, timed from just
// before write() to the reply's take (polled every 0.2 ms).
std::string cmd_apply(Peer& peer, const pj::Value& cmd) {
    using ReqPST = moveit_msgs::srv::ApplyPlanningScene_RequestPubSubType;
    using RespPST = moveit_msgs::srv::ApplyPlanningScene_ResponsePubSubType;
    using Req = moveit_msgs::srv::ApplyPlanningScene_Request;
    using Resp = moveit_msgs::srv::ApplyPlanningScene_Response;
    std::string service = cmd["service"].str();
    while (!service.empty() && service.front() == '/') service.erase(0, 1);
    DataWriter* w = peer.writer<ReqPST>("rq/" + service + "Request", kServiceQos);
    DataReader* r = peer.reader<RespPST>("rr/" + service + "Reply", kServiceQos);
    double timeout = cmd["timeout"].num(20);
    if (!wait_for([&] { return writer_matches(w) > 0 && reader_matches(r) > 0; }, timeout)) return pj::Obj().add("matched", "false").str();
    // Sends `req`; waits for its reply up to `wait` seconds (resending every `resend`).
    auto exchange = [&](Req& req, double wait, double resend) -> std::pair<int, double> {
        std::vector<int64_t> sent;
        double start = now_s(), end = start + wait, next = start;
        while (now_s() < end) {
            if (now_s() >= next) {
                rtps::WriteParams wp;
                wp.related_sample_identity().writer_guid(r->guid());
                if (w->write(&req, wp)) sent.push_back(seq_i64(wp.sample_identity().sequence_number()));
                next = resend > 0 ? now_s() + resend : end;
            }
            Resp resp;
            SampleInfo info;
            while (r->take_next_sample(&resp, &info) == ReturnCode_t::RETCODE_OK) {
                int64_t seq = seq_i64(info.related_sample_identity.sequence_number());
                if (info.valid_data && std::find(sent.begin(), sent.end(), seq) != sent.end()) return {resp.success() ? 1 : 0, now_s() - start};
            }
            sleep_s(0.0002);
        }
        return {-1, now_s() - start};
    };
    Req warm;
    warm.scene().is_diff(true);
    if (exchange(warm, timeout, 1.0).first != 1) return pj::Obj().add("matched", "true").add("error", pj::quote("no answer to the warm-up request")).str();
    std::vector<std::string> answers;
    for (const auto& f : cmd["files"].arr()) {
        Req req = decode_file<ReqPST, Req>(f.str());
        auto [ok, seconds] = exchange(req, timeout, 0.0);
        answers.push_back(pj::Obj().add("success", ok < 0 ? "null" : pj::boolean(ok == 1)).add("seconds", pj::number(seconds)).str());
    }
    return pj::Obj().add("matched", "true").add("answers", pj::array(answers, [](const std::string& x) { return x; })).str();
}

}  // namespace

int main(int argc, char** argv) {
    int domain = 0;
    if (const char* d = std::getenv("ROS_DOMAIN_ID")) domain = std::atoi(d);
    if (const char* pid = std::getenv("TC_FASTDDS_RELATED_SAMPLE_IDENTITY_PID")) g_pid = static_cast<uint16_t>(std::stoul(pid, nullptr, 16));
    std::string interface = "127.0.0.1";
    std::vector<std::string> peers;
    uint32_t receive_buffer = 0;  // 0: Fast DDS's default, the OS default socket buffer (as rmw_fastrtps_cpp)
    if (const char* b = std::getenv("TC_FASTDDS_RECEIVE_BUFFER")) receive_buffer = static_cast<uint32_t>(std::stoul(b));
    for (int i = 1; i + 1 < argc; i += 2) {
        std::string a = argv[i];
        if (a == "--domain") domain = std::atoi(argv[i + 1]);
        else if (a == "--interface") interface = argv[i + 1];
        else if (a == "--peer") peers.push_back(argv[i + 1]);
        else if (a == "--receive-buffer") receive_buffer = static_cast<uint32_t>(std::stoul(argv[i + 1]));
        else if (a == "--related-sample-identity-pid") g_pid = static_cast<uint16_t>(std::stoul(argv[i + 1], nullptr, 16));
        else {
            std::cerr << "usage: peer [--domain N] [--interface ADDRESS] [--peer ADDRESS]... [--related-sample-identity-pid 0x800f|0x0083|HEX] [--receive-buffer BYTES]" << std::endl;
            return 2;
        }
    }
    if (peers.empty()) peers.push_back("127.0.0.1");
    try {
        Peer peer(domain, interface, peers, g_pid != 0x800f, receive_buffer);
        std::string line;
        while (std::getline(std::cin, line)) {
            if (line.empty()) continue;
            std::string out;
            try {
                pj::Value cmd = pj::parse(line);
                std::string c = cmd["cmd"].str();
                if (c == "hello") out = pj::Obj().add("ok", "true").add("guid", pj::quote(peer.guid())).add("domain", pj::integer(domain)).add("related_sample_identity_pid", pj::integer(g_pid)).str();
                else if (c == "pid_stats") out = pj::Obj().add("rewritten", pj::integer(static_cast<int64_t>(g_rewritten.load()))).str();
                else if (c == "states") out = cmd_states(peer, cmd);
                else if (c == "description") out = cmd_description(peer, cmd);
                else if (c == "status") out = cmd_status(peer, cmd);
                else if (c == "latched") out = cmd_latched(peer, cmd);
                else if (c == "call") out = cmd_call(peer, cmd);
                else if (c == "apply") out = cmd_apply(peer, cmd);
                else if (c == "publish") out = cmd_publish(peer, cmd);
                else if (c == "quit") break;
                else throw std::runtime_error("unknown command '" + c + "'");
            } catch (const std::exception& e) {
                out = pj::Obj().add("error", pj::quote(e.what())).str();
            }
            std::cout << out << std::endl;
        }
    } catch (const std::exception& e) {
        std::cerr << "fastdds peer: " << e.what() << std::endl;
        return 1;
    }
    return 0;
}
