// The latency instrument (issue 14, parts 3 and 4), on Fast DDS 2.9, UDPv4 on 127.0.0.1 only:
// built-in transports off, no shared memory, no data sharing (the node's path: RustDDS on UDP).
//
//   latency measure  DOMAIN SECONDS WARMUP_S RATE_HZ...   JointState out, CollisionReport in; JSON per rate
//   latency interleave DOMAIN,DOMAIN... SECONDS WARMUP_S SLICE_S RATE_HZ...
//                                                         as measure, one answerer per domain, fed in
//                                                         turn SLICE_S at a time; JSON per rate and answerer
//   latency relay    DOMAIN                               answers each state with an empty report
//   latency latejoin DOMAIN TOPIC (markers|string) TIMEOUT_S   a late reader of a latched topic; JSON
//   latency latched  DOMAIN TOPIC BYTES SECONDS            publishes one latched std_msgs/String
//
// Built with tests/peers/fastdds/build.sh (benches/run_latency.sh does it). QoS as
// rmw_fastrtps_cpp makes them for what the node asks: joint_states best effort, keep last 100
// (the node's reader; a sensor stream), collisions reliable, volatile, keep last 100, synchronous
// publication, history memory preallocated with realloc; latched topics reliable, transient local,
// keep last 1.
//
// measure: a sender thread publishes at RATE_HZ, sleeping with clock_nanosleep(TIMER_ABSTIME) to
// SPIN_NS before each deadline and spinning for the rest (2 cores: a sleeping sender leaves the
// other core to the node). The stamp of each state is its send time (CLOCK_REALTIME, taken just
// before write()); a sender woken more than half a period late restarts its schedule from then
// (no catch-up burst; counted as "late_sends"); a report is matched to the state by its stamp, and latency is the report's
// receive time (CLOCK_REALTIME, in the listener) minus that stamp. "answered" counts states whose
// own stamp came back; with check_motion the node may cover several states waiting together with
// one report stamped with the newest: "covered" counts states at or before a stamp that came back.
#include "ros.h"
#include "rosPubSubTypes.h"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <thread>
#include <vector>

using namespace eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::Locator_t;

namespace {

constexpr int64_t SPIN_NS = 50'000;

int64_t now_ns(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// A participant on UDPv4 bound to 127.0.0.1, discovering by unicast to 127.0.0.1 (loopback has no
// multicast in a private namespace; the node's RustDDS answers unicast SPDP).
DomainParticipant* participant(int domain, const char* name) {
    DomainParticipantQos qos;
    qos.name(name);
    qos.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    qos.transport().user_transports.push_back(udp);
    Locator_t peer;
    peer.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
    qos.wire_protocol().builtin.initialPeersList.push_back(peer);
    qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(0, 500'000'000);
    auto* p = DomainParticipantFactory::get_instance()->create_participant(domain, qos);
    if (p == nullptr) {
        std::fprintf(stderr, "latency: cannot create the participant on domain %d\n", domain);
        std::exit(1);
    }
    return p;
}

DataWriterQos writer_qos(const DataWriterQos& base, bool reliable, bool latched, int depth) {
    DataWriterQos q = base;
    q.reliability().kind = reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    q.durability().kind = latched ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
    q.history().kind = KEEP_LAST_HISTORY_QOS;
    q.history().depth = depth;
    q.publish_mode().kind = SYNCHRONOUS_PUBLISH_MODE;
    q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    q.data_sharing().off();
    return q;
}

DataReaderQos reader_qos(const DataReaderQos& base, bool reliable, bool latched, int depth) {
    DataReaderQos q = base;
    q.reliability().kind = reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    q.durability().kind = latched ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
    q.history().kind = KEEP_LAST_HISTORY_QOS;
    q.history().depth = depth;
    q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    q.data_sharing().off();
    return q;
}

Topic* topic(DomainParticipant* p, const char* name, TopicDataType* type) {
    TypeSupport ts(type);
    ts.register_type(p);
    return p->create_topic(name, ts.get_type_name(), TOPIC_QOS_DEFAULT);
}

// ---- relay ----

struct RelayListener : DataReaderListener {
    DataWriter* writer = nullptr;
    sensor_msgs::msg::JointState state;
    thickness_collision_msgs::msg::CollisionReport report;
    void on_data_available(DataReader* reader) override {
        SampleInfo info;
        while (reader->take_next_sample(&state, &info) == ReturnCode_t::RETCODE_OK) {
            if (!info.valid_data) continue;
            report.header().stamp() = state.header().stamp();
            report.header().frame_id("world");
            writer->write(&report);
        }
    }
};

int relay(int domain) {
    auto* p = participant(domain, "latency_relay_cpp");
    auto* states = topic(p, "rt/joint_states", new sensor_msgs::msg::JointStatePubSubType());
    auto* reports = topic(p, "rt/collisions", new thickness_collision_msgs::msg::CollisionReportPubSubType());
    auto* pub = p->create_publisher(PUBLISHER_QOS_DEFAULT);
    auto* sub = p->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    static RelayListener listener;
    listener.writer = pub->create_datawriter(reports, writer_qos(pub->get_default_datawriter_qos(), true, false, 100));
    sub->create_datareader(states, reader_qos(sub->get_default_datareader_qos(), false, false, 100), &listener);
    std::printf("relay ready\n");
    std::fflush(stdout);
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(3600));
}

// ---- measure ----

struct Received {
    int64_t stamp;
    int64_t at;
    double check_seconds;
};

struct MeasureListener : DataReaderListener {
    std::vector<Received> got;
    std::atomic<size_t> n{0};
    std::atomic<int> matched{0};
    thickness_collision_msgs::msg::CollisionReport report;
    void on_data_available(DataReader* reader) override {
        SampleInfo info;
        while (reader->take_next_sample(&report, &info) == ReturnCode_t::RETCODE_OK) {
            int64_t at = now_ns(CLOCK_REALTIME);
            if (!info.valid_data) continue;
            size_t i = n.load(std::memory_order_relaxed);
            if (i < got.size()) {  // past the end only if reports outnumber states twice
                got[i] = {int64_t(report.header().stamp().sec()) * 1'000'000'000 + report.header().stamp().nanosec(), at, report.check_seconds()};
                n.store(i + 1, std::memory_order_release);
            }
        }
    }
    void on_subscription_matched(DataReader*, const SubscriptionMatchedStatus& s) override { matched = s.current_count; }
};

struct WriterMatch : DataWriterListener {
    std::atomic<int> matched{0};
    void on_publication_matched(DataWriter*, const PublicationMatchedStatus& s) override { matched = s.current_count; }
};

double pct(const std::vector<double>& sorted, double q) {
    if (sorted.empty()) return -1;
    size_t i = size_t(std::ceil(q * double(sorted.size()))) ;
    return sorted[std::min(sorted.size() - 1, i == 0 ? 0 : i - 1)];
}

// One answerer as the sender sees it: its own participant (each answerer runs on a domain of its
// own), the state writer and the report reader.
struct Endpoint {
    int domain = 0;
    DomainParticipant* participant = nullptr;
    DataWriter* writer = nullptr;
    WriterMatch wmatch;
    MeasureListener listener;
    // Per run: the send stamp of each state sent to this answerer, and its late sends.
    std::vector<int64_t> sent;
    size_t late = 0;
    int64_t worst_late = 0;
};

void open_endpoint(Endpoint& e, int domain, size_t room) {
    e.domain = domain;
    e.participant = participant(domain, "latency_measure");
    auto* states = topic(e.participant, "rt/joint_states", new sensor_msgs::msg::JointStatePubSubType());
    auto* reports = topic(e.participant, "rt/collisions", new thickness_collision_msgs::msg::CollisionReportPubSubType());
    auto* pub = e.participant->create_publisher(PUBLISHER_QOS_DEFAULT);
    auto* sub = e.participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    // A sensor stream as rmw_fastrtps_cpp offers SensorDataQoS: best effort, keep last 5.
    e.writer = pub->create_datawriter(states, writer_qos(pub->get_default_datawriter_qos(), false, false, 5), &e.wmatch);
    e.listener.got.resize(room);
    sub->create_datareader(reports, reader_qos(sub->get_default_datareader_qos(), true, false, 1000), &e.listener);
}

// One run at `rate`: every answerer is fed in turn, `slice` seconds at a time (the sender's
// schedule runs on across the switches), until each has had `warmup` + `seconds`; prints one JSON
// line per answerer.
void run_rate(std::vector<Endpoint*>& ends, double rate, double seconds, double warmup, double slice);

int measure(const std::vector<int>& domains, const std::vector<double>& rates, double seconds, double warmup, double slice) {
    double most = 0;
    for (double r : rates) most = std::max(most, r);
    std::vector<std::unique_ptr<Endpoint>> owned;
    std::vector<Endpoint*> ends;
    for (int d : domains) {
        owned.push_back(std::make_unique<Endpoint>());
        open_endpoint(*owned.back(), d, size_t(most * (seconds + warmup) * 2) + 1000);
        ends.push_back(owned.back().get());
    }
    int64_t t0 = now_ns(CLOCK_MONOTONIC);
    for (Endpoint* e : ends) {
        while (e->wmatch.matched == 0 || e->listener.matched == 0) {
            if (now_ns(CLOCK_MONOTONIC) - t0 > 30'000'000'000) {
                std::fprintf(stderr, "latency: no match within 30 s on domain %d (writer %d, reader %d)\n", e->domain, e->wmatch.matched.load(),
                             e->listener.matched.load());
                return 1;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    for (double rate : rates) {
        run_rate(ends, rate, seconds, warmup, slice);
    }
    // A clean exit: the peers learn at once that this participant's reader is gone (a reliable
    // writer matched to a reader that vanished without a word waits for it until its lease ends).
    for (Endpoint* e : ends) {
        e->participant->delete_contained_entities();
        DomainParticipantFactory::get_instance()->delete_participant(e->participant);
    }
    return 0;
}

void print_stats(const Endpoint& e, double rate, size_t warm) {
    size_t n = e.listener.n.load(std::memory_order_acquire);
    std::vector<Received> got(e.listener.got.begin(), e.listener.got.begin() + n);
    std::sort(got.begin(), got.end(), [](const Received& a, const Received& b) { return a.stamp < b.stamp; });
    std::vector<double> lat, check;
    std::vector<int64_t> answered_stamps;  // beside lat, in send order until lat is sorted
    size_t answered = 0, covered = 0, j = 0;
    int64_t newest = got.empty() ? INT64_MIN : got.back().stamp;
    for (size_t i = warm; i < e.sent.size(); ++i) {
        while (j < got.size() && got[j].stamp < e.sent[i]) ++j;
        if (j < got.size() && got[j].stamp == e.sent[i]) {
            ++answered;
            answered_stamps.push_back(e.sent[i]);
            lat.push_back(double(got[j].at - e.sent[i]) / 1e3);
            check.push_back(got[j].check_seconds * 1e6);
        }
        if (e.sent[i] <= newest) ++covered;
    }
    if (const char* dir = std::getenv("TC_LATENCY_DUMP")) {
        // Each answered state in send order (send stamp in ns, latency in µs), to see when the
        // tail happens: periodic (a timer in a stack) or scattered (the host).
        std::string path = std::string(dir) + "/" + std::to_string(e.domain) + "-" + std::to_string(int(rate)) + ".csv";
        if (FILE* f = std::fopen(path.c_str(), "w")) {
            for (size_t i = 0; i < lat.size(); ++i) std::fprintf(f, "%lld,%.1f\n", (long long)answered_stamps[i], lat[i]);
            std::fclose(f);
        } else {
            std::fprintf(stderr, "TC_LATENCY_DUMP: cannot write %s: %s\n", path.c_str(), std::strerror(errno));
        }
    }
    std::sort(lat.begin(), lat.end());
    std::sort(check.begin(), check.end());
    size_t measured = e.sent.size() - std::min(warm, e.sent.size());
    std::printf(
        "{\"domain\": %d, \"rate\": %.0f, \"sent\": %zu, \"answered\": %zu, \"covered\": %zu, \"median_us\": %.1f, \"p99_us\": %.1f, "
        "\"p999_us\": %.1f, \"max_us\": %.1f, \"late_sends\": %zu, \"worst_send_lateness_us\": %.1f, \"warmup_states\": %zu, "
        "\"check_median_us\": %.1f, \"check_p99_us\": %.1f}\n",
        e.domain, rate, measured, answered, covered, pct(lat, 0.5), pct(lat, 0.99), pct(lat, 0.999), lat.empty() ? -1.0 : lat.back(), e.late,
        double(e.worst_late) / 1e3, warm, pct(check, 0.5), pct(check, 0.99));
}

void run_rate(std::vector<Endpoint*>& ends, double rate, double seconds, double warmup, double slice) {
    const size_t warm = size_t(rate * warmup), each = warm + size_t(rate * seconds);
    const size_t per_slice = std::max<size_t>(1, size_t(rate * slice));
    for (Endpoint* e : ends) {
        e->listener.n.store(0, std::memory_order_release);  // got holds room for the largest run
        e->sent.clear();
        e->sent.reserve(each);
        e->late = 0;
        e->worst_late = 0;
    }
    // The bundled workcell's arm, moving slowly through free space (a motion for check_motion).
    // Each answerer sees a continuous motion of its own: its time runs only while it is fed.
    sensor_msgs::msg::JointState js;
    js.header().frame_id("");
    js.name({"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint",
             "finger_left_joint", "finger_right_joint"});
    js.position().assign(8, 0.0);
    const int64_t period = int64_t(1e9 / rate);
    int64_t deadline = now_ns(CLOCK_MONOTONIC) + period;
    auto feed = [&](Endpoint* e, size_t count) {
        for (size_t b = 0; b < count; ++b) {
            int64_t wake = deadline - SPIN_NS;
            timespec ts{time_t(wake / 1'000'000'000), long(wake % 1'000'000'000)};
            while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {}
            int64_t m;
            while ((m = now_ns(CLOCK_MONOTONIC)) < deadline) {}
            e->worst_late = std::max(e->worst_late, m - deadline);
            if (m - deadline > period / 2) {
                // Woken late (the machine stalled the sender): the schedule restarts from now rather
                // than catching up with a burst, which the node would rightly take as one motion.
                ++e->late;
                deadline = m;
            }
            double t = double(e->sent.size()) / rate;
            js.position()[0] = 0.3 * std::sin(2 * M_PI * 0.25 * t);
            js.position()[1] = -0.5 + 0.2 * std::sin(2 * M_PI * 0.2 * t);
            js.position()[2] = 0.8 + 0.2 * std::sin(2 * M_PI * 0.3 * t);
            js.position()[5] = 0.5 * t;
            int64_t stamp = now_ns(CLOCK_REALTIME);
            js.header().stamp().sec(int32_t(stamp / 1'000'000'000));
            js.header().stamp().nanosec(uint32_t(stamp % 1'000'000'000));
            e->sent.push_back(stamp);
            e->writer->write(&js);
            deadline += period;
        }
    };
    // The warm-up whole, each answerer in turn; then the slices, the answerers' order rotating
    // from one round of slices to the next so that none always follows the same one (a host's
    // stall, or a quiet spell, falls on all of them alike).
    for (Endpoint* e : ends) feed(e, warm);
    for (size_t r = 0;; ++r) {
        bool fed = false;
        for (size_t i = 0; i < ends.size(); ++i) {
            Endpoint* e = ends[(r + i) % ends.size()];
            if (e->sent.size() < each) {
                feed(e, std::min(per_slice, each - e->sent.size()));
                fed = true;
            }
        }
        if (!fed) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    for (Endpoint* e : ends) print_stats(*e, rate, warm);
    std::fflush(stdout);
}

// ---- late joiner and latched publisher (large messages) ----

struct LateListener : DataReaderListener {
    std::atomic<int64_t> at{0};
    std::atomic<int64_t> matched_at{0};
    std::atomic<int> matched{0};
    TopicDataType* type = nullptr;
    std::string summary;
    bool markers = false;
    void on_data_available(DataReader* reader) override {
        SampleInfo info;
        if (markers) {
            visualization_msgs::msg::MarkerArray m;
            while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
                if (!info.valid_data || at != 0) continue;
                size_t points = 0;
                for (auto& k : m.markers()) points += k.points().size();
                summary = "\"markers\": " + std::to_string(m.markers().size()) + ", \"points\": " + std::to_string(points) +
                          ", \"bytes\": " + std::to_string(type->getSerializedSizeProvider(&m)());
                at = now_ns(CLOCK_MONOTONIC);
            }
        } else {
            std_msgs::msg::String s;
            while (reader->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
                if (!info.valid_data || at != 0) continue;
                summary = "\"bytes\": " + std::to_string(s.data().size());
                at = now_ns(CLOCK_MONOTONIC);
            }
        }
    }
    void on_subscription_matched(DataReader*, const SubscriptionMatchedStatus& s) override {
        if (s.current_count > 0 && matched_at == 0) matched_at = now_ns(CLOCK_MONOTONIC);
        matched = s.current_count;
    }
};

int latejoin(int domain, const char* name, bool markers, double timeout) {
    int64_t t0 = now_ns(CLOCK_MONOTONIC);
    auto* p = participant(domain, "latency_latejoin");
    TopicDataType* type = markers ? static_cast<TopicDataType*>(new visualization_msgs::msg::MarkerArrayPubSubType())
                                  : static_cast<TopicDataType*>(new std_msgs::msg::StringPubSubType());
    auto* t = topic(p, name, type);
    auto* sub = p->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    static LateListener listener;
    listener.type = type;
    listener.markers = markers;
    sub->create_datareader(t, reader_qos(sub->get_default_datareader_qos(), true, true, 1), &listener);
    while (listener.at == 0 && now_ns(CLOCK_MONOTONIC) - t0 < int64_t(timeout * 1e9)) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    int64_t at = listener.at, m = listener.matched_at;
    if (at == 0) {
        std::printf("{\"topic\": \"%s\", \"received\": false, \"matched_ms\": %.1f}\n", name, m ? double(m - t0) / 1e6 : NAN);
    } else {
        std::printf("{\"topic\": \"%s\", \"received\": true, \"matched_ms\": %.1f, \"received_ms\": %.1f, \"after_match_ms\": %.1f, %s}\n", name,
                    double(m - t0) / 1e6, double(at - t0) / 1e6, double(at - m) / 1e6, listener.summary.c_str());
    }
    std::fflush(stdout);
    std::_Exit(at == 0 ? 3 : 0);
}

int latched(int domain, const char* name, size_t bytes, double seconds) {
    auto* p = participant(domain, "latency_latched");
    auto* t = topic(p, name, new std_msgs::msg::StringPubSubType());
    auto* pub = p->create_publisher(PUBLISHER_QOS_DEFAULT);
    auto* w = pub->create_datawriter(t, writer_qos(pub->get_default_datawriter_qos(), true, true, 1));
    std_msgs::msg::String s;
    std::string text = "<?xml version=\"1.0\"?>\n<!-- padding -->\n";
    text.resize(bytes, ' ');
    s.data(text);
    w->write(&s);
    std::printf("published %zu bytes\n", bytes);
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    std::_Exit(0);
}

}  // namespace

int main(int argc, char** argv) {
    std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "relay" && argc == 3) return relay(std::atoi(argv[2]));
    if (mode == "measure" && argc >= 6) {
        std::vector<double> rates;
        for (int i = 5; i < argc; ++i) rates.push_back(std::atof(argv[i]));
        return measure({std::atoi(argv[2])}, rates, std::atof(argv[3]), std::atof(argv[4]), std::atof(argv[3]));
    }
    if (mode == "interleave" && argc >= 7) {
        std::vector<int> domains;
        for (char* d = argv[2];;) {
            char* rest = nullptr;
            long v = std::strtol(d, &rest, 10);
            if (rest == d) break;
            domains.push_back(int(v));
            if (*rest != ',') break;
            d = rest + 1;
        }
        std::vector<double> rates;
        for (int i = 6; i < argc; ++i) rates.push_back(std::atof(argv[i]));
        return measure(domains, rates, std::atof(argv[3]), std::atof(argv[4]), std::atof(argv[5]));
    }
    if (mode == "latejoin" && argc == 6) return latejoin(std::atoi(argv[2]), argv[3], std::strcmp(argv[4], "markers") == 0, std::atof(argv[5]));
    if (mode == "latched" && argc == 6) return latched(std::atoi(argv[2]), argv[3], size_t(std::atoll(argv[4])), std::atof(argv[5]));
    std::fprintf(stderr,
                 "usage: latency measure DOMAIN SECONDS WARMUP_S RATE_HZ... | interleave DOMAIN,DOMAIN... SECONDS WARMUP_S SLICE_S RATE_HZ..."
                 " | relay DOMAIN | latejoin DOMAIN TOPIC markers|string TIMEOUT_S"
                 " | latched DOMAIN TOPIC BYTES SECONDS\n");
    return 2;
}
