// vk_compute.cpp — see vk_compute.h.
#include "vk_compute.h"

#include <vulkan/vulkan.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace prt::test {
namespace {

void check(VkResult r, const char* call) {
  if (r == VK_SUCCESS) return;
  std::ostringstream os;
  os << "Vulkan: " << call << " failed with VkResult " << static_cast<int>(r);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    os << " (VK_ERROR_INCOMPATIBLE_DRIVER: no Vulkan driver/ICD found — install mesa-vulkan-drivers for"
          " lavapipe, Mesa's CPU Vulkan device; tools/run.sh deps does)";
  throw std::runtime_error(os.str());
}
#define PRT_VK(call) check((call), #call)

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    default: return "other";
  }
}

std::string describe(const VkPhysicalDeviceProperties& p) {
  std::ostringstream os;
  os << p.deviceName << " (" << type_name(p.deviceType) << ", Vulkan " << VK_API_VERSION_MAJOR(p.apiVersion) << "."
     << VK_API_VERSION_MINOR(p.apiVersion) << "." << VK_API_VERSION_PATCH(p.apiVersion) << ")";
  return os.str();
}

std::vector<uint32_t> read_spirv(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open SPIR-V module (was the shader compiled by glslc?)");
  const auto size = static_cast<std::size_t>(in.tellg());
  if (size == 0 || size % 4 != 0)
    throw std::runtime_error(path + ": not a SPIR-V module (size " + std::to_string(size) + " is not a positive multiple of 4)");
  std::vector<uint32_t> words(size / 4);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(words.data()), static_cast<std::streamsize>(size));
  if (!in || words[0] != 0x07230203u) throw std::runtime_error(path + ": not a SPIR-V module (bad magic number)");
  return words;
}

} // namespace

struct VkCompute::State {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkPhysicalDeviceMemoryProperties memory{};
  std::string description;
  std::vector<std::string> all;

  ~State() {
    if (device != VK_NULL_HANDLE) vkDestroyDevice(device, nullptr);
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  }

  uint32_t host_memory_type(uint32_t allowed) const {
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i)
      if ((allowed & (1u << i)) && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
    throw std::runtime_error("Vulkan: device " + description + " has no host-visible coherent memory type");
  }
};

VkCompute::VkCompute() : state_(std::make_unique<State>()) {
  State& s = *state_;
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "prtbake shader-mirror tests";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  PRT_VK(vkCreateInstance(&ici, nullptr, &s.instance));

  uint32_t count = 0;
  PRT_VK(vkEnumeratePhysicalDevices(s.instance, &count, nullptr));
  if (count == 0)
    throw std::runtime_error("Vulkan: no physical device — install mesa-vulkan-drivers (lavapipe, Mesa's CPU Vulkan "
                             "driver); the shader-mirror tests need a device and do not skip");
  std::vector<VkPhysicalDevice> devices(count);
  PRT_VK(vkEnumeratePhysicalDevices(s.instance, &count, devices.data()));

  // Prefer a CPU device (lavapipe: deterministic, available in CI), then anything with compute.
  int best = -1, best_rank = -1;
  for (uint32_t d = 0; d < count; ++d) {
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(devices[d], &props);
    s.all.push_back(describe(props));
    uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(devices[d], &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(devices[d], &nq, families.data());
    const bool compute = std::any_of(families.begin(), families.end(),
                                     [](const VkQueueFamilyProperties& f) { return f.queueFlags & VK_QUEUE_COMPUTE_BIT; });
    if (!compute) continue;
    const int rank = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 1 : 0;
    if (rank > best_rank) {
      best = static_cast<int>(d);
      best_rank = rank;
    }
  }
  if (best < 0) {
    std::string list;
    for (const auto& a : s.all) list += "\n  " + a;
    throw std::runtime_error("Vulkan: no device with a compute queue among:" + list);
  }
  s.physical = devices[static_cast<std::size_t>(best)];
  s.description = s.all[static_cast<std::size_t>(best)];
  vkGetPhysicalDeviceMemoryProperties(s.physical, &s.memory);

  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical, &nq, families.data());
  for (uint32_t q = 0; q < nq; ++q)
    if (families[q].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      s.queue_family = q;
      break;
    }
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = s.queue_family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  PRT_VK(vkCreateDevice(s.physical, &dci, nullptr, &s.device));
  vkGetDeviceQueue(s.device, s.queue_family, 0, &s.queue);
}

VkCompute::~VkCompute() = default;

const std::string& VkCompute::device_description() const { return state_->description; }
const std::vector<std::string>& VkCompute::all_devices() const { return state_->all; }

void VkCompute::run(const std::string& spv_path, std::span<std::vector<std::byte>* const> buffers,
                    std::span<const std::byte> push, uint32_t groups_x) {
  State& s = *state_;
  VkDevice dev = s.device;
  const std::vector<uint32_t> code = read_spirv(spv_path);

  // Everything created here is destroyed at scope exit, also when a check throws.
  struct Scope {
    VkDevice dev;
    std::vector<VkBuffer> buffers;
    std::vector<VkDeviceMemory> memories;
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkCommandPool command_pool = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    ~Scope() {
      if (fence) vkDestroyFence(dev, fence, nullptr);
      if (command_pool) vkDestroyCommandPool(dev, command_pool, nullptr);
      if (pool) vkDestroyDescriptorPool(dev, pool, nullptr);
      if (pipeline) vkDestroyPipeline(dev, pipeline, nullptr);
      if (pipeline_layout) vkDestroyPipelineLayout(dev, pipeline_layout, nullptr);
      if (set_layout) vkDestroyDescriptorSetLayout(dev, set_layout, nullptr);
      if (module) vkDestroyShaderModule(dev, module, nullptr);
      for (VkBuffer b : buffers) vkDestroyBuffer(dev, b, nullptr);
      for (VkDeviceMemory m : memories) vkFreeMemory(dev, m, nullptr);
    }
  } sc{dev, {}, {}};

  const auto n = static_cast<uint32_t>(buffers.size());
  std::vector<VkDeviceSize> sizes(n);
  for (uint32_t k = 0; k < n; ++k) {
    sizes[k] = std::max<VkDeviceSize>(4, (buffers[k]->size() + 3) / 4 * 4);
    VkBufferCreateInfo bci{};
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = sizes[k];
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    PRT_VK(vkCreateBuffer(dev, &bci, nullptr, &buffer));
    sc.buffers.push_back(buffer);
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(dev, buffer, &req);
    VkMemoryAllocateInfo mai{};
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = s.host_memory_type(req.memoryTypeBits);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    PRT_VK(vkAllocateMemory(dev, &mai, nullptr, &memory));
    sc.memories.push_back(memory);
    PRT_VK(vkBindBufferMemory(dev, buffer, memory, 0));
    void* mapped = nullptr;
    PRT_VK(vkMapMemory(dev, memory, 0, sizes[k], 0, &mapped));
    std::memset(mapped, 0, static_cast<std::size_t>(sizes[k]));
    if (!buffers[k]->empty()) std::memcpy(mapped, buffers[k]->data(), buffers[k]->size());
    vkUnmapMemory(dev, memory);
  }

  VkShaderModuleCreateInfo smci{};
  smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  smci.codeSize = code.size() * 4;
  smci.pCode = code.data();
  PRT_VK(vkCreateShaderModule(dev, &smci, nullptr, &sc.module));

  std::vector<VkDescriptorSetLayoutBinding> bindings(n);
  for (uint32_t k = 0; k < n; ++k) {
    bindings[k].binding = k;
    bindings[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[k].descriptorCount = 1;
    bindings[k].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo dslci{};
  dslci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  dslci.bindingCount = n;
  dslci.pBindings = bindings.data();
  PRT_VK(vkCreateDescriptorSetLayout(dev, &dslci, nullptr, &sc.set_layout));

  VkPushConstantRange range{};
  range.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  range.size = static_cast<uint32_t>(push.size());
  VkPipelineLayoutCreateInfo plci{};
  plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &sc.set_layout;
  plci.pushConstantRangeCount = push.empty() ? 0 : 1;
  plci.pPushConstantRanges = &range;
  PRT_VK(vkCreatePipelineLayout(dev, &plci, nullptr, &sc.pipeline_layout));

  VkComputePipelineCreateInfo cpci{};
  cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpci.stage.module = sc.module;
  cpci.stage.pName = "main";
  cpci.layout = sc.pipeline_layout;
  PRT_VK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, nullptr, &sc.pipeline));

  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max<uint32_t>(n, 1)};
  VkDescriptorPoolCreateInfo dpci{};
  dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpci.maxSets = 1;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &pool_size;
  PRT_VK(vkCreateDescriptorPool(dev, &dpci, nullptr, &sc.pool));
  VkDescriptorSetAllocateInfo dsai{};
  dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  dsai.descriptorPool = sc.pool;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &sc.set_layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  PRT_VK(vkAllocateDescriptorSets(dev, &dsai, &set));
  std::vector<VkDescriptorBufferInfo> infos(n);
  std::vector<VkWriteDescriptorSet> writes(n);
  for (uint32_t k = 0; k < n; ++k) {
    infos[k] = VkDescriptorBufferInfo{sc.buffers[k], 0, VK_WHOLE_SIZE};
    writes[k].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[k].dstSet = set;
    writes[k].dstBinding = k;
    writes[k].descriptorCount = 1;
    writes[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[k].pBufferInfo = &infos[k];
  }
  vkUpdateDescriptorSets(dev, n, writes.data(), 0, nullptr);

  VkCommandPoolCreateInfo cpoolci{};
  cpoolci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cpoolci.queueFamilyIndex = s.queue_family;
  PRT_VK(vkCreateCommandPool(dev, &cpoolci, nullptr, &sc.command_pool));
  VkCommandBufferAllocateInfo cbai{};
  cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cbai.commandPool = sc.command_pool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  PRT_VK(vkAllocateCommandBuffers(dev, &cbai, &cmd));
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  PRT_VK(vkBeginCommandBuffer(cmd, &begin));
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, sc.pipeline);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, sc.pipeline_layout, 0, 1, &set, 0, nullptr);
  if (!push.empty())
    vkCmdPushConstants(cmd, sc.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, static_cast<uint32_t>(push.size()),
                       push.data());
  vkCmdDispatch(cmd, groups_x, 1, 1);
  // Make the shader writes visible to host reads after the fence.
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                       nullptr, 0, nullptr);
  PRT_VK(vkEndCommandBuffer(cmd));

  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  PRT_VK(vkCreateFence(dev, &fci, nullptr, &sc.fence));
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  PRT_VK(vkQueueSubmit(s.queue, 1, &submit, sc.fence));
  PRT_VK(vkWaitForFences(dev, 1, &sc.fence, VK_TRUE, UINT64_MAX));

  for (uint32_t k = 0; k < n; ++k) {
    void* mapped = nullptr;
    PRT_VK(vkMapMemory(dev, sc.memories[k], 0, sizes[k], 0, &mapped));
    if (!buffers[k]->empty()) std::memcpy(buffers[k]->data(), mapped, buffers[k]->size());
    vkUnmapMemory(dev, sc.memories[k]);
  }
}

VkCompute& vk_compute() {
  static VkCompute runner;  // a constructor that throws leaves it uninitialised: the next call retries
  return runner;
}

} // namespace prt::test
